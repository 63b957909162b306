"""``studies/probes/smoothed_objective.py``: its per-episode linear law is the shipped agent's
(the same validation cost with no gain noise), the gain perturbation is per episode (an
episode whose gains are zeroed costs the passive beam's 1 on its load), and agents that are not
one linear law, or perturbations of the wrong shape, are refused."""

from pathlib import Path

import numpy as np
import pytest

from studies.tests.probe_scripts import load_probe
from train.agent import TrainedAgent
from train.core.evaluate import validation_cost, validation_seeds

so = load_probe("smoothed_objective")

AGENTS = Path(__file__).resolve().parents[2] / "train" / "agents"


@pytest.mark.parametrize("name", ["vrs", "ppo"])
def test_law_without_noise_is_the_agents_validation_cost(name):
    agent = TrainedAgent.load(AGENTS / name)
    W, b = so.linear_law(agent.actor)
    seeds = validation_seeds(8)
    zero = np.zeros((len(seeds), W.size))
    # the same law through another product order: round-off, which 1000 closed-loop steps
    # amplify with the gains (acld-gym 0.15.0's ppo: 1.9e-9 relative; 0.14.0's within 1e-9)
    assert so.gain_noise_cost(W, b, zero, seeds) == pytest.approx(
        validation_cost(agent, seeds=seeds), rel=1e-8
    )


def test_gain_noise_is_per_episode():
    W, _ = so.linear_law(TrainedAgent.load(AGENTS / "vrs").actor)
    seeds = validation_seeds(4)
    dW = np.zeros((len(seeds), W.size))
    per_load = [so.gain_noise_cost(W, 0.0, dW[:1], [s]) for s in seeds]
    assert so.gain_noise_cost(W, 0.0, dW, seeds) == pytest.approx(np.mean(per_load), rel=1e-9)
    dW[0] = -W  # episode 0 without control: the passive beam, cost 1 on its load
    assert so.gain_noise_cost(W, 0.0, dW, seeds) == pytest.approx(
        np.mean([1.0, *per_load[1:]]), rel=1e-9
    )
    assert min(per_load) < 0.9  # so the passive episode did change the mean


def test_refuses_what_it_cannot_read():
    with pytest.raises(ValueError, match="actor: expected"):
        so.linear_law(TrainedAgent.load(AGENTS / "sac").actor)  # linear, clip, tanh
    W, b = so.linear_law(TrainedAgent.load(AGENTS / "vrs").actor)
    with pytest.raises(ValueError, match=r"dW: expected shape \(2, 9\)"):
        so.gain_noise_cost(W, b, np.zeros((3, 9)), validation_seeds(2))


def test_mean_action_law_is_the_expected_clipped_action():
    """The closed form against Monte Carlo of clip(W'z + b + eps'T'z) (2e5 draws), on
    observations where the clip is active on part of the distribution."""
    rng = np.random.default_rng(0)
    W, b = rng.normal(size=3), 0.2
    T = rng.normal(size=(3, 3))
    sigma = np.array([0.5, 0.2, 1.0])
    z = rng.normal(size=(4, 3))
    law = so._MeanActionLaw(W, b, sigma, T)
    volts, _ = law.predict(z)
    eps = rng.normal(size=(200_000, 3)) * sigma
    for k in range(len(z)):
        mc = np.clip(z[k] @ W + b + eps @ (T.T @ z[k]), -1.0, 1.0).mean()
        assert volts[k, 0] / 120.0 == pytest.approx(mc, abs=5e-3)
    assert np.ptp(volts) > 0 and np.all(np.abs(volts) < 120.0)  # not saturated: a mean


def test_mean_action_law_without_noise_is_the_clipped_mean():
    agent = TrainedAgent.load(AGENTS / "vrs")
    W, b = so.linear_law(agent.actor)
    seeds = validation_seeds(4)
    tiny = so._MeanActionLaw(W, b, np.full(W.size, 1e-12), np.eye(W.size))
    assert validation_cost(tiny, seeds=seeds) == pytest.approx(
        validation_cost(agent, seeds=seeds), rel=1e-9
    )
