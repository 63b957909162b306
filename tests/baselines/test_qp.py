"""Ctrl-C during an MPC's QP solve (issue 65): OSQP catches SIGINT itself and returns the
status "interrupted"; every MPC of the package reads its result through one function that
re-raises it as KeyboardInterrupt, so a command ends with run_main's one line and exit
status 130 instead of a RuntimeError traceback."""

from __future__ import annotations

from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401
from acld_gym.util.validate import run_main
from baselines.qp import solution


def _result(status: str):
    return SimpleNamespace(info=SimpleNamespace(status=status), x=np.array([0.25, 0.5]))


class _Solver:
    """An OSQP problem whose solve returns ``status``."""

    def __init__(self, status):
        self.status = status

    def update(self, **kwargs):
        pass

    def solve(self, raise_error=False):
        return _result(self.status)


def test_accepted_statuses_give_the_solution():
    for status in ("solved", "solved inaccurate"):
        assert solution(_result(status), "MPC")[0] == 0.25


def test_interrupted_is_a_keyboard_interrupt_and_other_statuses_name_the_solver():
    with pytest.raises(KeyboardInterrupt):
        solution(_result("interrupted"), "MPC")
    with pytest.raises(RuntimeError, match="mpc_oracle: OSQP returned status 'primal infeasible'"):
        solution(_result("primal infeasible"), "mpc_oracle")


def test_run_main_ends_an_interrupted_solve_with_one_line_and_130(capsys):
    assert run_main(lambda: solution(_result("interrupted"), "MPC"), prog="cmd") == 130
    assert capsys.readouterr().err == "cmd: interrupted\n"


def test_every_mpc_reads_its_result_through_it():
    pytest.importorskip("osqp")
    from baselines.engineer import ActuatorMPCPolicy
    from baselines.oracle import PlantOracleMPC
    from baselines.policies import MPCPolicy

    env = gym.make("ACLDBeam-v1")
    obs, _ = env.reset(seed=0)
    mpc = MPCPolicy.for_env(env, horizon=5)
    mpc._solvers[0] = _Solver("interrupted")
    with pytest.raises(KeyboardInterrupt):
        mpc.predict(obs)
    rig = ActuatorMPCPolicy.for_env(env, horizon=5)
    rig.mpc._solvers[0] = _Solver("interrupted")
    with pytest.raises(KeyboardInterrupt):
        rig.predict(obs)
    oracle = PlantOracleMPC(horizon=5)
    oracle.start_episode(env)
    oracle._prob = _Solver("interrupted")
    with pytest.raises(KeyboardInterrupt):
        oracle.predict(obs)
    oracle._prob = _Solver("max iterations reached")
    with pytest.raises(RuntimeError, match="mpc_oracle: OSQP returned status"):
        oracle.predict(obs)
