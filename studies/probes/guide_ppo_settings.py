"""A probe of the guide's SB3 PPO script (docs/examples/sb3_ppo.py) with some of its
settings as arguments, each defaulting to the script's value: the entropy coefficient
(``--ent``, 0.05), the discount (``--gamma``, 0.999), the actor's hidden layers (``--pi``,
JSON, ``[]``: a linear law), gSDE (``--no-sde``: plain Gaussian noise), the epochs
(``--epochs``, 5) and the minibatch (``--batch``, 512); everything else is the script's.
Not a test; ~1.5 min a run on one core::

    python studies/probes/guide_ppo_settings.py ACLDBeamHard-v1 --seed 101 --ent 0
    python studies/probes/guide_ppo_settings.py ACLDBeamHard-v1 --seed 7 --pi "[64, 64]"
"""

import argparse
import json
from functools import partial

import gymnasium as gym
import torch
from stable_baselines3 import PPO
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
p.add_argument("--timesteps", type=arg_type(int, 1), default=2_000_000)
p.add_argument("--seed", type=arg_type(int, 0, 2**32 - 1), default=0)  # numpy's range
p.add_argument("--episodes", type=int, help="score on the first N test loads (default: all)")
p.add_argument("--save", type=arg_save_dir, metavar="DIR", help="keep the model and VecNormalize")
p.add_argument("--ent", type=float, default=0.05)
p.add_argument("--gamma", type=float, default=0.999)
p.add_argument("--pi", type=json.loads, default=[])
p.add_argument("--sde", action=argparse.BooleanOptionalAction, default=True)
p.add_argument("--epochs", type=int, default=5)
p.add_argument("--batch", type=int, default=512)
args = p.parse_args()
n_test = len(evaluation_set(args.env_id).seeds)  # checked now, not after training
if args.episodes is not None and not 1 <= args.episodes <= n_test:
    p.error(f"argument --episodes: expected an integer in [1, {n_test}], got {args.episodes}")
torch.set_num_threads(1)  # torch's default threads make SB3 15-25x slower on 2 cores

modes = preset(args.env_id).obs_mode == "estimate"  # mode 1 and the tip, where observed
venv = VecNormalize(
    SB3VecEnv(
        venv=gym.make_vec(args.env_id, 256, load_case="random", reward_scale="passive"),
        wrappers=[vector.UnitAction] + [partial(vector.ObserveModes, modes=1)] * modes,
    ),
    gamma=args.gamma,
)
model = PPO(
    "MlpPolicy", venv, n_steps=64, batch_size=args.batch, n_epochs=args.epochs, gamma=args.gamma, gae_lambda=0.98,  # noqa: E501
    learning_rate=lambda progress: 3e-3 * progress, ent_coef=args.ent, use_sde=args.sde,
    policy_kwargs=dict(net_arch=dict(pi=args.pi, vf=[64, 64]), log_std_init=-1.0), seed=args.seed,
)  # fmt: skip
model.learn(args.timesteps)
if args.save is not None:  # score later: score(PPO.load(...), ..., vec_normalize=the .pkl)
    save_run(model, args.save)
wrappers = [UnitAction] + [partial(ObserveModes, modes=1)] * modes  # the same, one env
print(score(model, args.env_id, wrappers=wrappers, episodes=args.episodes))
