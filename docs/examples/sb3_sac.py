"""SB3 SAC with MlpPolicy on any ACLDBeam level, scored: python sb3_sac.py [ENV_ID]."""

import argparse
from functools import partial

import gymnasium as gym
import torch
from stable_baselines3 import SAC
from stable_baselines3.common.vec_env import VecNormalize

from acld_gym.envs import SB3VecEnv
from acld_gym.envs.presets import PRESETS, preset
from acld_gym.test_sets import evaluation_set
from acld_gym.util.validate import arg_type
from acld_gym.wrappers import ObserveModes, UnitAction, vector
from train.sb3_save import arg_save_dir, save_run
from train.scoring import score

p = argparse.ArgumentParser()
p.add_argument("env_id", nargs="?", default="ACLDBeam-v1", choices=list(PRESETS))
p.add_argument("--timesteps", type=arg_type(int, 10_001), default=300_000)  # > learning_starts
p.add_argument("--seed", type=arg_type(int, 0, 2**32 - 1), default=0)  # numpy's range
p.add_argument("--episodes", type=int, help="score on the first N test loads (default: all)")
p.add_argument("--save", type=arg_save_dir, metavar="DIR", help="keep the model and VecNormalize")
args = p.parse_args()
n_test = len(evaluation_set(args.env_id).seeds)  # checked now, not after training
if args.episodes is not None and not 1 <= args.episodes <= n_test:
    p.error(f"argument --episodes: expected an integer in [1, {n_test}], got {args.episodes}")
torch.set_num_threads(1)  # torch's default threads make SB3 15-25x slower on 2 cores

modes = preset(args.env_id).obs_mode == "estimate"  # mode 1 and the tip, where observed
venv = VecNormalize(
    SB3VecEnv(
        venv=gym.make_vec(args.env_id, 16, load_case="random", reward_scale="passive"),
        wrappers=[partial(vector.UnitAction, headroom=3.0)]
        + [partial(vector.ObserveModes, modes=1)] * modes,
    ),
    gamma=0.995,
)
model = SAC(
    "MlpPolicy", venv, buffer_size=300_000, batch_size=1024, learning_starts=10_000,
    gamma=0.995, n_steps=5, learning_rate=1e-3, gradient_steps=2,
    policy_kwargs=dict(net_arch=dict(pi=[], qf=[64, 64])), seed=args.seed,
)  # fmt: skip
model.learn(args.timesteps)
if args.save is not None:  # score later: score(SAC.load(...), ..., vec_normalize=the .pkl)
    save_run(model, args.save)
wrappers = [partial(UnitAction, headroom=3.0)] + [partial(ObserveModes, modes=1)] * modes
print(score(model, args.env_id, wrappers=wrappers, episodes=args.episodes))
