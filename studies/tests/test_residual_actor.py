"""``studies/probes/residual_actor.py``: the residual actor's latent is ``[u, h(u)]`` (its mean is
the linear law plus a nonlinear correction), folding the whitening into it keeps the law on
the raw observation (the package's fold calls the policy's own), gSDE's noise acts on
the whole latent or on the linear gains alone, and a bad ``hidden`` or ``noise`` is refused
by name."""

import functools

import gymnasium as gym
import numpy as np
import pytest
import torch

import train.core.sb3_train as sb3_train
from studies.tests.probe_scripts import load_probe, tiny_model
from train.core.sb3_policies import SB3Policy

ra = load_probe("residual_actor")


def _model(noise: str = "latent"):
    return tiny_model(ra.config([8], noise))[0]


@pytest.fixture
def model():
    return _model()


@functools.cache
def _width() -> int:
    """The env's observation width (the env built once)."""
    return gym.make("ACLDBeam-v1").observation_space.shape[0]


def _obs(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, _width())).astype(np.float32)


def test_the_mean_is_the_linear_law_plus_a_nonlinear_correction(model):
    net, head = model.policy.mlp_extractor.policy_net, model.policy.action_net
    d = _width()
    assert isinstance(net, ra.Residual) and head.in_features == d + 8
    u = torch.as_tensor(_obs(6, 1))
    with torch.no_grad():
        latent = net(u)
        assert torch.equal(latent[:, :d], u)  # the linear part sees u itself (T = I)
        assert torch.allclose(latent[:, d:], net.mlp(u))
        h = latent[:, d:]
        assert not torch.allclose(net(2 * u)[:, d:], 2 * h)  # and the rest is nonlinear


def test_folding_the_whitening_keeps_the_law_on_the_raw_observation(model):
    """The package's fold (what ``train_sb3`` calls when training ends) hands the whitening
    to the policy's own ``fold_whitening``: the law on the raw observation is the law on the
    whitened one."""
    with torch.no_grad():  # gains large enough that the correction and the clip both show
        model.policy.action_net.weight.normal_(0.0, 0.3, generator=torch.Generator().manual_seed(0))
    T = np.random.default_rng(2).normal(size=(_width(),) * 2)
    z = _obs(64, 3)
    before, _ = SB3Policy(model, None, None, transform=T).predict(z)
    sb3_train.fold_whitening(model, T)
    after, _ = SB3Policy(model, None, None).predict(z)
    assert 0 < np.mean(np.abs(before) < 120.0) < 1  # some inside the limit, some at it
    np.testing.assert_allclose(after, before, atol=1e-3)
    assert not np.allclose(model.policy.mlp_extractor.policy_net.T.numpy(), np.eye(len(T)))


@pytest.mark.parametrize("noise, moves", [("latent", True), ("linear", False)])
def test_noise_acts_on_the_whole_latent_or_on_the_linear_gains_alone(noise, moves):
    """gSDE's action noise (its std per observation) depends on the MLP's features with
    ``noise="latent"`` and not with ``"linear"``; the mean depends on them either way."""
    model = _model(noise)
    obs = torch.as_tensor(np.concatenate([_obs(6, 4), np.zeros((6, 1), np.float32)], axis=1))

    def dist():
        with torch.no_grad():
            d = model.policy.get_distribution(obs).distribution
        return d.mean.clone(), d.stddev.clone()

    mean0, std0 = dist()
    with torch.no_grad():
        for p in model.policy.mlp_extractor.policy_net.mlp.parameters():
            p.add_(torch.randn(p.shape, generator=torch.Generator().manual_seed(5)))
        model.policy.action_net.weight.fill_(0.1)  # so the mean reads the features
    mean1, std1 = dist()
    assert not torch.allclose(mean0, mean1)
    assert torch.allclose(std0, std1) is not moves


@pytest.mark.parametrize("hidden", [[], [0], [64, -1]])
def test_bad_hidden_is_refused_by_name(hidden):
    with pytest.raises(ValueError, match=r"hidden: expected one or more positive widths"):
        ra.ResidualActorPolicy(
            gym.spaces.Box(-1, 1, (3,)), gym.spaces.Box(-1, 1, (1,)), lambda _: 1e-3, hidden=hidden
        )


def test_bad_noise_is_refused_by_name():
    with pytest.raises(ValueError, match=r"noise: expected one of \['latent', 'linear'\]"):
        ra.ResidualActorPolicy(
            gym.spaces.Box(-1, 1, (3,)), gym.spaces.Box(-1, 1, (1,)), lambda _: 1e-3, noise="h"
        )


def test_on_the_0_15_recipe_the_noise_comes_in_antithetic_pairs():
    """``--recipe ppo``: acld-gym 0.15.0's recipe (paired sub-envs, the never-positive
    critic) with the residual actor, whose gSDE matrices come in pairs E, -E."""
    cfg = ra.config([8], recipe="ppo")
    assert cfg.paired_loads and cfg.restarts == 1
    assert cfg.model["policy_kwargs"]["critic_features"] == "negative_scaled_quadratic"
    policy = tiny_model(cfg)[0].policy
    policy.reset_noise(4)
    e = policy.action_dist.exploration_matrices
    assert torch.equal(e[1::2], -e[0::2]) and not torch.equal(e[0], e[2])
