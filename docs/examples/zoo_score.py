"""Score an rl-zoo3 run of train/zoo/*_mlp.yml: python zoo_score.py ALGO RUN [ENV_ID]."""

import argparse
from pathlib import Path

import torch
from rl_zoo3 import ALGOS
from rl_zoo3.utils import get_saved_hyperparams, get_wrapper_class

from acld_gym.envs.presets import PRESETS
from train.scoring import score

p = argparse.ArgumentParser()
p.add_argument("algo", choices=["ppo", "sac"])
p.add_argument("run", type=Path, help="rl-zoo3's run folder, e.g. logs/ppo/ACLDBeam-v1_1")
p.add_argument("env_id", nargs="?", default="ACLDBeam-v1", choices=list(PRESETS))
p.add_argument("--episodes", type=int, help="score on the first N test loads (default: all)")
args = p.parse_args()
torch.set_num_threads(1)  # torch's default threads make SB3 15-25x slower on 2 cores

saved = args.run / args.env_id  # rl-zoo3's record of the run: its settings, VecNormalize
hyperparams, _ = get_saved_hyperparams(str(saved))
model = ALGOS[args.algo].load(args.run / f"{args.env_id}.zip", device="cpu")
wrappers = [get_wrapper_class(hyperparams)]  # its env_wrapper list, as one callable
vecnorm = saved / "vecnormalize.pkl"
print(score(model, args.env_id, wrappers=wrappers, vec_normalize=vecnorm, episodes=args.episodes))
