"""A probe of the guide's SB3 SAC script (docs/examples/sb3_sac.py) with the fixed ZCA
whitening of ``guide_ppo_whiten.py`` (:func:`guide_ppo_whiten.whitening_transform`) before
``VecNormalize``. Everything else is the script's. The script learns next to nothing on
``ACLDBeamHard-v1`` (score -0.03 to 0.03 on seeds 101-103, docs/any-library.md), whose
observation is a window of 8 tip measurements, nearly collinear at 1 kHz, on which a linear
actor's gradient is badly conditioned. Not a test; ~9 min a run on one core (515 s on
2026-12-08's host)::

    python studies/probes/guide_sac_whiten.py ACLDBeamHard-v1 --seed 7
"""

import argparse
import sys
from functools import partial
from pathlib import Path

import gymnasium as gym
import torch
from stable_baselines3 import SAC
from stable_baselines3.common.vec_env import VecNormalize

from acld_gym.envs import SB3VecEnv
from acld_gym.envs.presets import preset
from acld_gym.wrappers import ObserveModes, UnitAction, WhitenObservation, vector
from train.scoring import score

sys.path.insert(0, str(Path(__file__).resolve().parent))
from guide_ppo_whiten import whitening_transform  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("env_id")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--timesteps", type=int, default=300_000)
    p.add_argument("--noise", type=float, default=0.1)
    args = p.parse_args()
    torch.set_num_threads(1)
    modes = preset(args.env_id).obs_mode == "estimate"
    T = whitening_transform(args.env_id, modes, 1, args.noise)
    venv = VecNormalize(
        SB3VecEnv(
            venv=gym.make_vec(args.env_id, 16, load_case="random", reward_scale="passive"),
            wrappers=[partial(vector.UnitAction, headroom=3.0)]
            + [partial(vector.ObserveModes, modes=1)] * modes
            + [partial(vector.WhitenObservation, transform=T)],
        ),
        gamma=0.995,
    )
    model = SAC(
        "MlpPolicy", venv, buffer_size=300_000, batch_size=1024, learning_starts=10_000,
        gamma=0.995, n_steps=5, learning_rate=1e-3, gradient_steps=2,
        policy_kwargs=dict(net_arch=dict(pi=[], qf=[64, 64])), seed=args.seed,
    )  # fmt: skip
    model.learn(args.timesteps)
    wrappers = [partial(UnitAction, headroom=3.0)] + [partial(ObserveModes, modes=1)] * modes
    wrappers += [partial(WhitenObservation, transform=T)]
    print(score(model, args.env_id, wrappers=wrappers, vec_normalize=venv))


if __name__ == "__main__":
    main()
