"""``studies/probes/episode_noise.py``: gSDE's standard-normal draw is held per sub-env for a
whole episode, across SB3's per-rollout noise requests, scaled by the current sigma, and
redrawn when the episode's steps are done."""

import numpy as np
import torch

from studies.tests.probe_scripts import load_probe, tiny_model

en = load_probe("episode_noise")


def _policy():
    model, width = tiny_model(en.config())
    return model.policy, width


def test_the_draw_is_held_across_rollouts_and_scaled_by_the_current_sigma():
    policy, _ = _policy()
    policy.reset_noise(4)
    eps = policy.eps.clone()
    first = policy.action_dist.exploration_matrices.detach().clone()
    std = policy.action_dist.get_std(policy.log_std).detach()
    torch.testing.assert_close(first, eps * std)
    with torch.no_grad():
        policy.log_std += np.log(2.0)  # a PPO update doubles sigma
    policy.reset_noise(4)  # the next rollout's request
    assert torch.equal(policy.eps, eps)
    torch.testing.assert_close(policy.action_dist.exploration_matrices.detach(), 2 * first)
    assert len(set(eps.flatten().tolist())) == eps.numel()  # one draw per sub-env and gain


def test_the_draw_is_renewed_after_an_episode_of_steps():
    policy, width = _policy()
    policy.reset_noise(4)
    eps = policy.eps.clone()
    obs = torch.zeros((4, width))
    with torch.no_grad():
        for _ in range(en.EPISODE_STEPS):
            policy(obs)
        assert torch.equal(policy.eps, eps)  # the whole episode on one draw
        policy(obs)  # the first step of the next episode
    assert not torch.equal(policy.eps, eps)
    std = policy.action_dist.get_std(policy.log_std).detach()
    torch.testing.assert_close(policy.action_dist.exploration_matrices.detach(), policy.eps * std)


def test_on_the_0_15_recipe_the_draws_come_in_antithetic_pairs():
    """``--recipe ppo``: acld-gym 0.15.0's recipe (sub-envs in pairs), and each draw, the
    first and every renewed one, gives sub-env 2i + 1 the negative of 2i's."""
    cfg = en.config(hold=3, recipe="ppo")
    assert cfg.paired_loads and cfg.restarts == 1
    assert cfg.model["policy_kwargs"]["critic_features"] == "negative_scaled_quadratic"
    model, width = tiny_model(cfg)
    policy = model.policy
    policy.reset_noise(4)
    first = policy.eps.clone()
    with torch.no_grad():
        for _ in range(4):  # past the 3-step hold: a renewed draw
            policy(torch.zeros((4, width)))
    for eps in (first, policy.eps):
        assert torch.equal(eps[1::2], -eps[0::2]) and not torch.equal(eps[0], eps[2])
    assert not torch.equal(policy.eps, first)
