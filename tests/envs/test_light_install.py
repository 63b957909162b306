"""The env without the training stack (issue 11, light extras): ``import acld_gym`` and
``gym.make`` work in an environment without torch, SB3, osqp, yaml or tqdm. The imports
are blocked in a subprocess, the way a core-only install lacks them
(:func:`tests.core_only.run_core_only`)."""

from __future__ import annotations

from tests.core_only import BLOCKED, run_core_only

CODE = f"""
import numpy as np, gymnasium as gym
import acld_gym
for env_id in ("ACLDBeam-v1", "ACLDBeam-v0"):
    env = gym.make(env_id, load_case="random")
    obs, _ = env.reset(seed=0)
    for _ in range(10):
        obs, *_ = env.step(np.array([50.0], np.float32))
vec = gym.make_vec("ACLDBeam-v1", num_envs=4)
vec.reset(seed=0)
vec.step(np.zeros((4, 1)))
from acld_gym.thesis.reproduce import run_cases
loaded = sorted(m for m in sys.modules if m.split('.')[0] in {BLOCKED + ("tqdm",)!r})
print("ok", loaded)
"""


def test_env_works_without_the_training_stack():
    out = run_core_only(CODE, blocked_extra=("tqdm",))
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok []"
