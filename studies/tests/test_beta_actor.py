"""``studies/probes/beta_actor.py``: the Beta policy's actions lie in [-1, 1] with the density
of ``2 x - 1``, ``x ~ Beta(alpha, beta)``, its deterministic action is that mean, its
parameters are linear in the observation, and folding the whitening keeps the law."""

import numpy as np
import torch

import train.core.sb3_train as sb3_train
from studies.tests.probe_scripts import load_probe, tiny_model
from train.core.sb3_policies import SB3Policy

ba = load_probe("beta_actor")


def _dist(params):
    return ba.BetaDistribution(1).proba_distribution(torch.as_tensor(params, dtype=torch.float64))


def test_the_density_is_that_of_two_x_minus_one():
    """Integrated over [-1, 1] the density is 1, and its mean and entropy are the
    integrals of a and -log p."""
    d = _dist([[0.3, -1.2]])
    a = torch.linspace(-1 + 1e-9, 1 - 1e-9, 200001, dtype=torch.float64)[:, None]
    p = torch.exp(d.log_prob(a))
    np.testing.assert_allclose(torch.trapezoid(p, a[:, 0]).item(), 1.0, atol=1e-6)
    np.testing.assert_allclose(
        torch.trapezoid(p * a[:, 0], a[:, 0]).item(), d.mode().item(), atol=1e-6
    )
    np.testing.assert_allclose(
        torch.trapezoid(-p * torch.log(p), a[:, 0]).item(), d.entropy().item(), atol=1e-5
    )


def test_samples_lie_in_the_range_with_the_distributions_mean():
    d = _dist(np.tile([[2.0, -0.5]], (20000, 1)))
    s = d.sample()
    assert s.min() > -1 and s.max() < 1
    np.testing.assert_allclose(s.mean().item(), d.mode()[0].item(), atol=0.01)
    alpha, beta = 1 + np.log1p(np.exp(2.0)), 1 + np.log1p(np.exp(-0.5))
    np.testing.assert_allclose(d.mode()[0].item(), (alpha - beta) / (alpha + beta), rtol=1e-12)


def test_the_policy_acts_with_the_beta_and_folding_the_whitening_keeps_its_law():
    model, width = tiny_model(ba.config())
    policy = model.policy
    assert isinstance(policy.action_dist, ba.BetaDistribution) and not model.use_sde
    assert policy.action_net.in_features == width - 1  # the actor drops log c
    trained = [p for g in policy.optimizer.param_groups for p in g["params"]]
    assert any(p is policy.action_net.weight for p in trained)  # the Beta head is trained
    with torch.no_grad():
        policy.action_net.weight.normal_(0.0, 1.0, generator=torch.Generator().manual_seed(0))
    T = np.random.default_rng(2).normal(size=(width - 1,) * 2)
    z = np.random.default_rng(3).normal(size=(64, width - 1)).astype(np.float32)
    before, _ = SB3Policy(model, None, None, transform=T).predict(z)
    sb3_train.fold_whitening(model, T)
    after, _ = SB3Policy(model, None, None).predict(z)
    assert np.all(np.abs(before) < 120.0) and np.std(before) > 10.0
    np.testing.assert_allclose(after, before, atol=1e-3)
