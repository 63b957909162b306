"""A plain single-file PyTorch PPO on ACLDBeam-v1, with only what docs/training.md's section
"Any library: the Gymnasium env, and what to add" tells it to add (its paragraph "A plain
single-file PyTorch PPO"), and its ISE / LQR through the env.

The file is the user's own copy of CleanRL's ``cleanrl/ppo_continuous_action.py`` (not part of
this repository). This script makes that paragraph's edits to a temporary copy, nothing else:

1. ``import acld_gym`` and ``from acld_gym.wrappers import ObserveModes, UnitAction``;
2. in ``make_env``, ``gym.make(env_id)`` becomes
   ``ObserveModes(UnitAction(gym.make(env_id, load_case="random", reward_scale="passive")),
   modes=1)``;
3. (Gymnasium 1.x, any env) ``TransformObservation`` gets its third argument,
   ``env.observation_space``.

It runs the copy (``--env-id ACLDBeam-v1 --total-timesteps N --seed S --no-cuda``, then the
file's own flags given after ``--``, none by default; torch on one thread unless
``OMP_NUM_THREADS`` says otherwise), and to
measure it saves the trained agent with its ``NormalizeObservation`` statistics (an appended
instrumentation block, after training), then evaluates the deterministic actor (its mean,
clipped to [-1, 1], times 120 V, on the observation slots ``ObserveModes`` keeps) on the
plain env: thesis cases 1, 2, 3 (seed 0) and the held-out random set, divided by LQR's ISE
(:mod:`train.core.evaluate`).

Needs ``pip install tyro`` (the file's own import; tensorboard, its other one, comes with
the ``[train]`` extra). Not a test::

    python benchmarks/single_file_ppo.py path/to/ppo_continuous_action.py --seed 1
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

#: Torch's threads in the run, unless OMP_NUM_THREADS is set: one. A one-env PPO gains
#: nothing from more, and two runs side by side on 2 cores with torch's default took over
#: 70 min each instead of 11.
THREADS = os.environ.get("OMP_NUM_THREADS", "1")
MAKE = "env = gym.make(env_id)"
CLIP_OBS = "lambda obs: np.clip(obs, -10, 10))"
CLIP_OBS_1X = "lambda obs: np.clip(obs, -10, 10), env.observation_space)"
#: The modes ``ObserveModes`` keeps (mode 1 and the tip: with modes 1 and 2, seed 2 ended at
#: 2.05x LQR on case 1, with mode 1 only at 0.93x; docs/training.md).
MODES = 1
EDIT = (
    'env = ObserveModes(UnitAction(gym.make(env_id, load_case="random", '
    f'reward_scale="passive")), modes={MODES})'
)
IMPORTS = "import acld_gym  # noqa\nfrom acld_gym.wrappers import ObserveModes, UnitAction\n"
SAVE = """
# --- instrumentation (benchmarks/single_file_ppo.py): save the agent and its normalization ---
import pickle as _pickle
_norm = envs.envs[0]
while not isinstance(_norm, gym.wrappers.NormalizeObservation):
    _norm = _norm.env
with open({out!r}, "wb") as _f:
    _actor = {{k: v.cpu().numpy() for k, v in agent.actor_mean.state_dict().items()}}
    _pickle.dump({{"actor": _actor, "mean": _norm.obs_rms.mean, "var": _norm.obs_rms.var}}, _f)
"""


def edited_source(text: str, out: Path) -> str:
    """The page's edits (the imports, ``make_env``'s env, ``TransformObservation``'s space)
    and the instrumentation block; ``ValueError`` if the file is not the expected CleanRL
    script."""
    if text.count(MAKE) < 1 or "def make_env" not in text or "__main__" not in text:
        raise ValueError(
            f"file: expected CleanRL's ppo_continuous_action.py (a make_env with {MAKE!r})"
        )
    lines = text.splitlines(keepends=True)
    at = next(i for i, line in enumerate(lines) if line.startswith("import gymnasium"))
    text = "".join(lines[: at + 1]) + IMPORTS + "".join(lines[at + 1 :])
    text = text.replace(MAKE, EDIT).replace(CLIP_OBS, CLIP_OBS_1X)
    main_at = text.index("    if args.save_model:")
    block = "".join(
        "    " + line + "\n" if line else "\n" for line in SAVE.format(out=str(out)).splitlines()
    )
    return text[:main_at] + block + text[main_at:]


class _Actor:
    """The deterministic actor of the saved file as an SB3-``predict`` policy in volts, on
    the env's full observation (``slots``: the entries the trained agent saw)."""

    def __init__(self, saved: dict, slots=None):
        self.layers = [
            (saved["actor"][f"{i}.weight"], saved["actor"][f"{i}.bias"]) for i in (0, 2, 4)
        ]
        self.mean, self.var = saved["mean"], saved["var"]
        self.slots = None if slots is None else np.asarray(slots)

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        x = np.asarray(obs, dtype=np.float64)
        if self.slots is not None:
            x = x[..., self.slots]
        z = np.clip((x - self.mean) / np.sqrt(self.var + 1e-8), -10, 10)
        for i, (W, b) in enumerate(self.layers):
            z = z @ W.T + b
            if i < 2:
                z = np.tanh(z)
        v = 120.0 * np.clip(z, -1.0, 1.0)
        return v.astype(np.float32).reshape(x.shape[:-1] + (1,)), state


def split_flags(argv: list) -> tuple[list, list]:
    """This script's arguments and, after ``--``, the file's own flags."""
    cut = argv.index("--") if "--" in argv else len(argv)
    return argv[:cut], argv[cut + 1 :]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("file", type=Path, help="CleanRL's ppo_continuous_action.py")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--total-timesteps", type=int, default=1_000_000)
    p.add_argument("--json", type=Path, default=None, help="write the figures here")
    own, flags = split_flags(list(sys.argv[1:] if argv is None else argv))
    args = p.parse_args(own)
    from train.core.evaluate import ise_rel_lqr

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        saved = tmp / "agent.pkl"
        script = tmp / "ppo_continuous_action.py"
        script.write_text(edited_source(args.file.read_text(), saved))
        t0 = time.perf_counter()
        subprocess.run(
            [
                sys.executable,
                str(script),
                "--env-id",
                "ACLDBeam-v1",
                "--total-timesteps",
                str(args.total_timesteps),
                "--seed",
                str(args.seed),
                "--no-cuda",
                *flags,
            ],
            cwd=tmp,
            check=True,
            env={**os.environ, "OMP_NUM_THREADS": THREADS},
            stdout=subprocess.DEVNULL,
        )
        wall = time.perf_counter() - t0
        import pickle

        from acld_gym.envs.beam_env import ACLDBeamEnv
        from acld_gym.wrappers import ObserveModes

        slots = ObserveModes(ACLDBeamEnv(), modes=MODES).slots
        actor = _Actor(pickle.loads(saved.read_bytes()), slots)
    rel = ise_rel_lqr(actor, "ACLDBeam-v1")
    out = {
        "seed": args.seed,
        "total_timesteps": args.total_timesteps,
        "flags": flags,
        "wall_seconds": wall,
        "ise_rel_lqr": {str(k): float(v) for k, v in rel.items()},
    }
    print(json.dumps(out, indent=1))
    if args.json is not None:
        from acld_gym.util.atomic import write_text

        write_text(args.json, json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
