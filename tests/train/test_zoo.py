"""rl-zoo3's hyperparameter files (train/zoo/*.yml): the same recipe as the benchmark's, and
(slow) rl-zoo3 trains and replays both algorithms from them."""

from __future__ import annotations

import subprocess
import sys

import pytest
import yaml

ZOO_ONLY = {"env_wrapper", "env_kwargs", "n_envs", "n_timesteps", "policy", "policy_kwargs",
            "learning_rate"}


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_zoo_file_is_the_benchmark_recipe(algo):
    zoo = yaml.safe_load(open(f"train/zoo/{algo}.yml"))["ACLDBeam-v1"]
    bench = yaml.safe_load(open(f"train/benchmark/{algo}.yaml"))
    headroom = bench.get("action_headroom", 1.0)
    if headroom == 1.0:
        assert zoo["env_wrapper"] == ["acld_gym.wrappers.UnitAction"]
    else:  # the wrapper's headroom, and the critic's (AsymmetricSACPolicy), are the recipe's
        assert zoo["env_wrapper"] == [{"acld_gym.wrappers.UnitAction": {"headroom": headroom}}]
    assert zoo["env_kwargs"] == {"load_case": "random", **bench["env_kwargs"]}
    assert bench["loads"] == {"random": 1}
    assert zoo["n_envs"] == bench["n_envs"] and zoo["n_timesteps"] == bench["timesteps"]
    assert zoo["policy"] == f"train.bench.sb3_policies.{bench['model']['policy']}"
    model = {k: v for k, v in bench["model"].items() if k not in ZOO_ONLY}
    assert {k: zoo[k] for k in model} == model
    lr = bench["model"]["learning_rate"]
    if isinstance(lr, dict):  # rl-zoo3's "lin_<start>" decays linearly to 0
        assert lr["linear"][1] == 0 and zoo["learning_rate"].startswith("lin_")
        assert float(zoo["learning_rate"][4:]) == lr["linear"][0]
    else:
        assert zoo["learning_rate"] == lr
    kwargs = eval(zoo["policy_kwargs"])  # rl-zoo3 evaluates the string the same way
    if headroom != 1.0:
        assert kwargs.pop("action_headroom") == headroom
    assert kwargs == bench["model"]["policy_kwargs"]


@pytest.mark.slow
@pytest.mark.parametrize("algo, extra", [
    ("ppo", ["n_envs:4", "n_steps:64", "batch_size:256"]),
    ("sac", ["n_envs:4", "learning_starts:200", "batch_size:64"]),
])
def test_rl_zoo3_trains_and_replays(tmp_path, algo, extra):
    pytest.importorskip("rl_zoo3")
    common = ["--algo", algo, "--env", "ACLDBeam-v1", "--gym-packages", "acld_gym",
              "-f", str(tmp_path)]
    subprocess.run([sys.executable, "-m", "rl_zoo3.train", *common, "--conf-file",
                    f"train/zoo/{algo}.yml", "-n", "1024", "--seed", "0", "--eval-freq", "-1",
                    "--hyperparams", *extra], check=True, capture_output=True)
    assert (tmp_path / algo / "ACLDBeam-v1_1" / "ACLDBeam-v1.zip").is_file()
    out = subprocess.run([sys.executable, "-m", "rl_zoo3.enjoy", *common, "--no-render",
                          "-n", "1100", "--env-kwargs", "load_case:1"], check=True,
                         capture_output=True, text=True)
    assert "Loading" in out.stdout + out.stderr
