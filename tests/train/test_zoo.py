"""rl-zoo3's hyperparameter files (train/zoo/*.yml): the same recipe as the benchmark's, and
(slow) rl-zoo3 trains and replays both algorithms from them."""

from __future__ import annotations

import subprocess
import sys

import pytest
import yaml

ZOO_ONLY = {
    "env_wrapper",
    "env_kwargs",
    "n_envs",
    "n_timesteps",
    "policy",
    "policy_kwargs",
    "learning_rate",
}


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_zoo_file_is_the_benchmark_recipe(algo):
    zoo = yaml.safe_load(open(f"train/zoo/{algo}.yml"))["ACLDBeam-v1"]
    bench = yaml.safe_load(open(f"train/recipes/{algo}.yaml"))
    headroom = bench.get("action_headroom", 1.0)
    if headroom == 1.0:
        assert zoo["env_wrapper"] == ["acld_gym.wrappers.UnitAction"]
    else:  # the wrapper's headroom, and the critic's (AsymmetricSACPolicy), are the recipe's
        assert zoo["env_wrapper"] == [{"acld_gym.wrappers.UnitAction": {"headroom": headroom}}]
    assert zoo["env_kwargs"] == {"load_case": "random", **bench["env_kwargs"]}
    assert bench["loads"] == {"random": 1}
    assert zoo["n_envs"] == bench["n_envs"] and zoo["n_timesteps"] == bench["timesteps"]
    assert zoo["policy"] == f"train.core.sb3_policies.{bench['model']['policy']}"
    model = {k: v for k, v in bench["model"].items() if k not in ZOO_ONLY}
    assert {k: zoo[k] for k in model} == model
    lr = bench["model"]["learning_rate"]
    if isinstance(lr, dict) and lr["linear"][1] == 0:  # rl-zoo3's "lin_<start>": to 0
        assert zoo["learning_rate"].startswith("lin_")
        assert float(zoo["learning_rate"][4:]) == lr["linear"][0]
    elif isinstance(lr, dict):  # any other end: the callback train.zoo.LinearLearningRate
        start, end = lr["linear"]
        assert zoo["learning_rate"] == start
        assert {"train.zoo.LinearLearningRate": {"start": start, "end": end}} in zoo["callback"]
    else:
        assert zoo["learning_rate"] == lr
    text = open(f"train/zoo/{algo}.yml").read()
    restarts = bench.get("restarts", 1)  # rl-zoo3 trains one run; the file says how to do more
    assert restarts == 1 or f"restarts: {restarts}" in text
    # rl-zoo3 seeds its sub-envs seed + i: the file says it cannot pair them
    assert not bench.get("paired_loads") or "paired_loads" in text
    kwargs = eval(zoo["policy_kwargs"])  # rl-zoo3 evaluates the string the same way
    if headroom != 1.0:
        assert kwargs.pop("action_headroom") == headroom
    assert kwargs == bench["model"]["policy_kwargs"]


def test_zoo_learning_rate_callback_gives_the_model_its_schedule():
    """rl-zoo3 builds the callback from the file, and the model trains at its rates."""
    from rl_zoo3.utils import get_callback_list
    from stable_baselines3 import SAC

    from train.zoo import LinearLearningRate

    hp = yaml.safe_load(open("train/zoo/sac.yml"))["ACLDBeam-v1"]
    (callback,) = [c for c in get_callback_list(hp) if isinstance(c, LinearLearningRate)]
    # as rl-zoo3 gives it, a constant (its start), from which the callback takes over
    model = SAC(
        "MlpPolicy",
        "Pendulum-v1",
        learning_rate=hp["learning_rate"],
        learning_starts=0,
        batch_size=8,
        seed=0,
    )
    assert model.actor.optimizer.param_groups[0]["lr"] == hp["learning_rate"]
    model.learn(400, callback=callback)
    start, end = callback.schedule(1.0), callback.schedule(0.0)
    assert (start, end) == (1e-3, 5e-4)
    for optimizer in (model.actor.optimizer, model.critic.optimizer):
        # the last update at progress remaining 1/400 (SB3 counts it before the update)
        assert optimizer.param_groups[0]["lr"] == pytest.approx(end, abs=2e-6)


@pytest.mark.parametrize("start, end", [(0.0, 1e-4), (-1e-3, 0.0), (1e-3, -1e-4), ("1e-3", 0.0)])
def test_zoo_learning_rate_callback_rejects_bad_rates(start, end):
    from train.zoo import LinearLearningRate

    name = "start" if start != 1e-3 else "end"
    with pytest.raises(ValueError, match=name):
        LinearLearningRate(start, end)


@pytest.mark.slow
@pytest.mark.parametrize(
    "algo, extra",
    [
        ("ppo", ["n_envs:4", "n_steps:64", "batch_size:256"]),
        ("sac", ["n_envs:4", "learning_starts:200", "batch_size:64"]),
    ],
)
def test_rl_zoo3_trains_and_replays(tmp_path, algo, extra):
    pytest.importorskip("rl_zoo3")
    common = [
        "--algo",
        algo,
        "--env",
        "ACLDBeam-v1",
        "--gym-packages",
        "acld_gym",
        "-f",
        str(tmp_path),
    ]
    subprocess.run(
        [
            sys.executable,
            "-m",
            "rl_zoo3.train",
            *common,
            "--conf-file",
            f"train/zoo/{algo}.yml",
            "-n",
            "1024",
            "--seed",
            "0",
            "--eval-freq",
            "-1",
            "--hyperparams",
            *extra,
        ],
        check=True,
        capture_output=True,
    )
    assert (tmp_path / algo / "ACLDBeam-v1_1" / "ACLDBeam-v1.zip").is_file()
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "rl_zoo3.enjoy",
            *common,
            "--no-render",
            "-n",
            "1100",
            "--env-kwargs",
            "load_case:1",
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    assert "Loading" in out.stdout + out.stderr
