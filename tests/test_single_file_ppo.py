"""``benchmarks/single_file_ppo.py``: the edits it makes to a user's copy of CleanRL's PPO are
the documented ones (docs/training.md, "Any library: the Gymnasium env, and what to add")
and nothing else, its ``make_env`` line builds a ``check_env``-clean env, and the saved
actor is evaluated on the same observation slots it was trained on."""

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import acld_gym  # noqa: F401
from acld_gym.wrappers import ObserveModes, UnitAction
from tests.benchmark_scripts import load_script

sfp = load_script("single_file_ppo")

# The shape of CleanRL's ppo_continuous_action.py where the script edits it.
CLEANRL_LIKE = """import numpy as np
import gymnasium as gym
import torch


def make_env(env_id, idx, capture_video, run_name, gamma):
    def thunk():
        env = gym.make(env_id)
        env = gym.wrappers.NormalizeObservation(env)
        env = gym.wrappers.TransformObservation(env, lambda obs: np.clip(obs, -10, 10))
        return env

    return thunk


if __name__ == "__main__":
    agent = None
    if args.save_model:
        pass
"""


def test_edits_are_the_documented_ones_and_nothing_else(tmp_path):
    out = tmp_path / "agent.pkl"
    text = sfp.edited_source(CLEANRL_LIKE, out)
    assert sfp.IMPORTS in text and sfp.EDIT in text and sfp.CLIP_OBS_1X in text
    assert "gym.make(env_id)\n" not in text
    assert text.index("instrumentation") < text.index("if args.save_model:")
    assert repr(str(out)) in text
    # undoing the three edits and the block gives the file back
    start = text.index("\n    # --- instrumentation")
    block = text[start : text.index("    if args.save_model:")]
    undone = (
        text.replace(sfp.IMPORTS, "")
        .replace(sfp.EDIT, sfp.MAKE)
        .replace(sfp.CLIP_OBS_1X, sfp.CLIP_OBS)
        .replace(block, "")
    )
    assert undone == CLEANRL_LIKE
    compile(text, "ppo_continuous_action.py", "exec")


def test_other_files_are_refused():
    with pytest.raises(ValueError, match="file: expected CleanRL"):
        sfp.edited_source("print('hello')\n", Path("x.pkl"))


def test_the_make_env_line_builds_a_clean_env():
    env_id = "ACLDBeam-v1"
    scope = {"gym": gym, "env_id": env_id, "ObserveModes": ObserveModes, "UnitAction": UnitAction}
    exec(sfp.EDIT, scope)
    env = scope["env"]
    check_env(env, skip_render_check=True)
    assert env.observation_space.shape == (3,)  # mode 1 (two states) and the tip
    assert env.action_space.low[0] == -1.0 and env.action_space.high[0] == 1.0
    assert env.unwrapped.config.load_case == "random"


def test_actor_reads_the_trained_slots_and_returns_volts():
    rng = np.random.default_rng(0)
    layers = {
        f"{i}.weight": rng.normal(size=shape)
        for i, shape in ((0, (4, 3)), (2, (4, 4)), (4, (1, 4)))
    }
    layers.update({f"{i}.bias": rng.normal(size=n) for i, n in ((0, 4), (2, 4), (4, 1))})
    saved = {"actor": layers, "mean": rng.normal(size=3), "var": rng.uniform(1, 2, 3)}
    env = gym.make("ACLDBeam-v1").unwrapped
    slots = ObserveModes(env, modes=sfp.MODES).slots
    actor = sfp._Actor(saved, slots)
    obs = rng.normal(size=(5, env.observation_space.shape[0]))
    v, _ = actor.predict(obs)
    z = np.clip((obs[:, slots] - saved["mean"]) / np.sqrt(saved["var"] + 1e-8), -10, 10)
    z = np.tanh(z @ layers["0.weight"].T + layers["0.bias"])
    z = np.tanh(z @ layers["2.weight"].T + layers["2.bias"])
    z = z @ layers["4.weight"].T + layers["4.bias"]
    assert v.shape == (5, 1) and v.dtype == np.float32
    np.testing.assert_allclose(v, 120.0 * np.clip(z, -1, 1), rtol=1e-6)
    assert np.all(np.abs(v) <= 120.0)


def test_flags_after_the_separator_are_the_files():
    assert sfp.split_flags(["f.py", "--seed", "3", "--", "--num-envs", "8"]) == (
        ["f.py", "--seed", "3"],
        ["--num-envs", "8"],
    )
    assert sfp.split_flags(["f.py"]) == (["f.py"], [])
