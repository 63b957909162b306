"""``studies/probes/objective_headroom.py``: the certainty-equivalent MPC of the env's reward
tends to the passive beam as its voltage weight grows (validation cost 1, by the passive
scale's construction), beats LQR on the env's own objective at the env's weight, and bad
arguments are named."""

import json

import gymnasium as gym
import numpy as np
import pytest

import acld_gym
from baselines.policies import LQRPolicy
from studies.tests.probe_scripts import load_probe
from train.core.evaluate import validation_cost, validation_seeds

oh = load_probe("objective_headroom")
SEEDS = validation_seeds(4)


@pytest.fixture(scope="module")
def env():
    return gym.make(acld_gym.ENV_ID)


def test_a_prohibitive_voltage_weight_gives_the_passive_beam(env):
    # the passive policy's scaled cost is exactly 1 (acld_gym.envs.scale); a weight of 1e8
    # on (V / 120)^2 against (y / 1 mm)^2 leaves voltages of microvolts
    cost = validation_cost(oh.mpc(env, 1e8), acld_gym.ENV_ID, SEEDS)
    assert cost == pytest.approx(1.0, abs=1e-6)


def test_at_the_env_weight_the_mpc_beats_lqr_on_the_env_objective(env):
    lam = env.unwrapped.config.lam
    mpc = validation_cost(oh.mpc(env, lam), acld_gym.ENV_ID, SEEDS)
    lqr = validation_cost(LQRPolicy.for_env(env), acld_gym.ENV_ID, SEEDS)
    assert mpc < 0.98 * lqr < 1.0


def test_one_line_per_policy(capsys):
    assert oh.main(["--rho", "0.01", "--loads", "2"]) == 0
    lines = [json.loads(s) for s in capsys.readouterr().out.splitlines()]
    assert [d["policy"] for d in lines] == ["lqr", "mpc rho=0.01"]
    np.testing.assert_array_equal(lines[0]["ise_rel_lqr"], [1.0, 1.0, 1.0, 1.0])
    assert 0 < lines[1]["validation_cost"] < lines[0]["validation_cost"] < 1


@pytest.mark.parametrize(
    "argv, named",
    [(["--loads", "0"], "--loads"), (["--rho", "-1"], "--rho"), (["--horizon", "0"], "--horizon")],
)
def test_bad_arguments_are_named(argv, named, capsys):
    with pytest.raises(SystemExit) as exc:
        oh.main(argv)
    assert exc.value.code == 2
    assert named in capsys.readouterr().err
