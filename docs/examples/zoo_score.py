"""Score an rl-zoo3 run of train/zoo/*_mlp.yml: python zoo_score.py ALGO RUN [ENV_ID]."""

import argparse
import sys
from pathlib import Path

import torch
import yaml
from rl_zoo3 import ALGOS
from rl_zoo3.utils import get_saved_hyperparams, get_wrapper_class

from acld_gym.envs.presets import PRESETS, check_env_id
from acld_gym.test_sets import evaluation_set
from train.scoring import score

p = argparse.ArgumentParser()
p.add_argument("algo", choices=["ppo", "sac"])
p.add_argument("run", type=Path, help="rl-zoo3's run folder, e.g. logs/ppo/ACLDBeam-v1_1")
p.add_argument("env_id", nargs="?", choices=list(PRESETS), help="default: the run's")
p.add_argument("--episodes", type=int, help="score on the first N test loads (default: all)")
args = p.parse_args()
record = list(args.run.glob("*/args.yml"))  # rl-zoo3's record of the run's command line
if len(record) != 1:
    p.error(f"argument run: expected rl-zoo3's run folder (<env id>/args.yml in it): {args.run}")
try:  # YAML nodes (its OrderedDict's [key, value] pairs), their strings: no python tag is run
    pairs = yaml.compose(record[0].read_text()).value[0].value
    ran = {k.value: v.value for k, v in (kv.value for kv in pairs) if v.tag.endswith(":str")}
    algo, env_id = ran["algo"], check_env_id(ran["env"], "env")
except Exception as exc:  # anything wrong with the file: one line, not a traceback
    sys.exit(f"{p.prog}: error: {record[0]}: not rl-zoo3's args.yml: {' '.join(str(exc).split())}")
if args.algo != algo:
    p.error(f"argument algo: {args.run} is an rl-zoo3 {algo} run, not {args.algo}")
if args.env_id not in (None, env_id):
    p.error(f"argument env_id: {args.run} trained on {env_id}, not {args.env_id}")
n_test = len(evaluation_set(env_id).seeds)
if args.episodes is not None and not 1 <= args.episodes <= n_test:
    p.error(f"argument --episodes: expected an integer in [1, {n_test}], got {args.episodes}")
torch.set_num_threads(1)  # torch's default threads make SB3 15-25x slower on 2 cores

saved = args.run / env_id  # rl-zoo3's record of the run: its settings, VecNormalize
vecnorm, zipped = saved / "vecnormalize.pkl", args.run / f"{env_id}.zip"
for needed in (saved / "config.yml", vecnorm, zipped):
    if not needed.is_file():
        sys.exit(f"{p.prog}: error: {needed}: not found (a run that did not finish?)")
hyperparams, _ = get_saved_hyperparams(str(saved))
model = ALGOS[algo].load(zipped, device="cpu")
wrappers = [get_wrapper_class(hyperparams)]  # its env_wrapper list, as one callable
print(score(model, env_id, wrappers=wrappers, vec_normalize=vecnorm, episodes=args.episodes))
