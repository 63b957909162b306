"""The modal test: the passive beam's identified modes are the model's, and a linear
policy's identified closed-loop modes are the exact eigenvalues of its sampled loop."""

from pathlib import Path

import numpy as np
import pytest

from acld_gym.design.nominal import nominal_design
from baselines.analysis.linear import ObserverLoop, small_signal_law
from baselines.analysis.modal import modal_test
from baselines.policies import LQRPolicy, MPCPolicy, PassivePolicy, SMCPolicy
from train.agent import TrainedAgent
from train.compare import AGENTS_DIR

#: Agents with known faults (described in the README of tests/data/agents).
FIXTURES = Path(__file__).resolve().parents[2] / "data" / "agents"


def model_modes(n=3):
    """(frequency, damping ratio) of the continuous truth plant's first n modes."""
    truth = nominal_design().truth
    lam = np.linalg.eigvals(truth.state_space(truth.params)[0])
    lam = lam[lam.imag > 0]
    lam = lam[np.argsort(np.abs(lam))][:n]
    return np.abs(lam), -lam.real / np.abs(lam)


def test_passive_modes_are_the_models(rig, passive):
    w, zeta = model_modes()
    for ident in (passive[0], modal_test(PassivePolicy(), rig, passive[1], 120.0).modes):
        for m, wi, zi in zip(ident, w, zeta, strict=True):
            assert m.damping_ratio == pytest.approx(zi, rel=0.05)
            assert m.frequency_rad_s == pytest.approx(wi, rel=0.01)
            assert m.damping_ratio == pytest.approx(zi, rel=1e-3)  # in fact much closer


@pytest.mark.parametrize(
    "make",
    [LQRPolicy, SMCPolicy, MPCPolicy, lambda: TrainedAgent.load(AGENTS_DIR / "vrs")],
    ids=["lqr", "smc", "mpc", "vrs"],
)
def test_identified_closed_loop_modes_are_the_exact_eigenvalues(rig, passive, make):
    pol = make()
    _, edges = passive
    test = modal_test(pol, rig, edges, 120.0)
    assert test.valid, test.reason
    assert test.max_voltage_V < 120.0 and test.linearity_error < 1e-4
    law, why = small_signal_law(pol, 9, 120.0)
    assert law is not None, why
    exact = ObserverLoop.from_env(rig.env).modes(law, edges, 2000)
    for m, e in zip(test.modes, exact, strict=True):
        assert m.frequency_rad_s == pytest.approx(e.frequency_rad_s, rel=0.01)
        assert m.damping_ratio == pytest.approx(e.damping_ratio, rel=0.05)
    assert test.check["damping_change"] < 0.05  # the order check agrees


def test_lqr_adds_damping_to_mode_1_where_the_beam_has_least(rig, passive):
    test = modal_test(LQRPolicy(), rig, passive[1], 120.0)
    assert test.modes[0].damping_ratio > 5 * passive[0][0].damping_ratio
    assert 6 <= test.identification.order <= 30


@pytest.mark.parametrize("name, word", [("ppo_dagger", "limit"), ("sac_0.2", "rest")])
def test_policies_without_a_rest_state_have_no_modes(rig, passive, name, word):
    test = modal_test(TrainedAgent.load(FIXTURES / name), rig, passive[1], 120.0)
    assert not test.valid and not test.rests and word in test.reason
    assert test.modes == [None, None, None]
