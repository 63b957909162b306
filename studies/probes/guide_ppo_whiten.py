"""A probe of the guide's SB3 PPO script (docs/examples/sb3_ppo.py) with a fixed ZCA
whitening of the observation (:func:`acld_gym.wrappers.whitening` of the directions of 64
episodes with a uniform random voltage of +/- ``--noise`` of the limit, random loads)
before ``VecNormalize``, the package's recipes' conditioning for a plain ``MlpPolicy``.
Everything else is the script's. Not a test; ~1.5 min a run on one core::

    python studies/probes/guide_ppo_whiten.py ACLDBeamHard-v1 --seed 101
"""

import argparse
from functools import partial

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import VecNormalize

from acld_gym.envs import SB3VecEnv
from acld_gym.envs.presets import preset
from acld_gym.wrappers import ObserveModes, UnitAction, WhitenObservation, vector, whitening
from train.scoring import score


def sample_directions(env_id: str, modes: bool, n_modes: int = 1, noise: float = 0.1):
    """The directions z/|z| (rows) of the observations of 64 episodes with a random voltage
    (uniform, +/- ``noise`` of the limit), random loads, as the scripts' policy sees them
    (``UnitAction``, ``ObserveModes`` where ``modes``); zero observations left out."""
    venv0 = gym.make_vec(env_id, 64, load_case="random")
    venv0 = vector.UnitAction(venv0)
    if modes:
        venv0 = vector.ObserveModes(venv0, modes=n_modes)
    rng = np.random.default_rng(12345)
    obs, _ = venv0.reset(seed=12345)
    zs = []
    for _ in range(1000):
        zs.append(obs.copy())
        obs, *_ = venv0.step(rng.uniform(-noise, noise, (64, 1)).astype(np.float32))
    venv0.close()
    z = np.concatenate(zs)
    z = z[np.linalg.norm(z, axis=1) > 0]
    return z / np.linalg.norm(z, axis=1, keepdims=True)


def whitening_transform(env_id: str, modes: bool, n_modes: int = 1, noise: float = 0.1):
    """T, the ZCA whitening of :func:`sample_directions`."""
    return whitening(sample_directions(env_id, modes, n_modes, noise))


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("env_id")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--timesteps", type=int, default=2_000_000)
    p.add_argument("--noise", type=float, default=0.1)
    p.add_argument("--modes", type=int, default=1)
    p.add_argument("--norm", type=int, default=1)
    args = p.parse_args()
    torch.set_num_threads(1)
    modes = preset(args.env_id).obs_mode == "estimate" and args.modes > 0
    T = whitening_transform(args.env_id, modes, args.modes, args.noise)

    venv = SB3VecEnv(
        venv=gym.make_vec(args.env_id, 256, load_case="random", reward_scale="passive"),
        wrappers=[vector.UnitAction]
        + [partial(vector.ObserveModes, modes=args.modes)] * modes
        + [partial(vector.WhitenObservation, transform=T)],
    )
    venv = VecNormalize(venv, gamma=0.999, norm_obs=bool(args.norm))
    model = PPO(
        "MlpPolicy", venv, n_steps=64, batch_size=512, n_epochs=5, gamma=0.999, gae_lambda=0.98,
        learning_rate=lambda progress: 3e-3 * progress, ent_coef=0.05, use_sde=True,
        policy_kwargs=dict(net_arch=dict(pi=[], vf=[64, 64]), log_std_init=-1.0), seed=args.seed,
    )  # fmt: skip
    model.learn(args.timesteps)
    wrappers = [UnitAction] + [partial(ObserveModes, modes=args.modes)] * modes
    wrappers += [partial(WhitenObservation, transform=T)]
    print(score(model, args.env_id, wrappers=wrappers, vec_normalize=venv if args.norm else None))


if __name__ == "__main__":
    main()
