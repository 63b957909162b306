"""``studies/probes/noise_anneal.py``: the actor's log std is left alone until the fraction
``start`` of the run's rollouts, then capped linearly from ``log_std_init`` down to ``final``
at the last rollout; a one-env draw (``PPO.load``, a single rollout) is not counted."""

import torch

import train.core.sb3_train as sb3_train
from studies.tests.probe_scripts import load_probe, tiny_model

na = load_probe("noise_anneal")


def test_the_cap_follows_the_schedule(monkeypatch):
    monkeypatch.setattr(sb3_train, "AsymmetricCriticPolicy", na.AnnealedNoisePolicy)
    cfg = na.one_run(None, {"rollouts": 10, "start": 0.5, "final": -3.0}, base="ppo")
    model, _ = tiny_model(cfg)
    policy = model.policy
    assert isinstance(policy, na.AnnealedNoisePolicy) and policy.init == -1.0
    caps = []
    for draw in range(1, 11):
        with torch.no_grad():
            policy.log_std.fill_(0.0)  # as if PPO had pushed the noise up
        policy.reset_noise(1)  # not a rollout's draw: uncounted, uncapped
        assert policy.draws == draw - 1 and float(policy.log_std.detach().max()) == 0.0
        policy.reset_noise(4)
        caps.append(round(float(policy.log_std.detach().max()), 6))
    # draws 1-5 (half the run) free, then -1 -> -3 linearly over draws 6-10
    assert caps == [0.0] * 5 + [-1.4, -1.8, -2.2, -2.6, -3.0]
    std = policy.action_dist.get_std(policy.log_std).detach()
    assert torch.allclose(std, torch.full_like(std, torch.exp(torch.tensor(-3.0)).item()))


def test_voltage_weight_changes_only_the_training_envs_weight():
    from train.vec import make_vec_env

    vw = load_probe("voltage_weight")
    base = na.one_run(None, base="ppo")
    cfg = vw.config(0.03)
    assert cfg.env_kwargs == {**base.env_kwargs, "lam": 0.03}
    assert cfg.model == base.model and cfg.restarts == 1
    venv = make_vec_env(cfg, 0, "ACLDBeam-v1")
    try:
        inner = venv
        while hasattr(inner, "venv"):  # VecNormalize, VecWhiten, ... down to the native env
            inner = inner.venv
        assert inner.config.lam == 0.03
    finally:
        venv.close()


def test_ppo_settings_replaces_only_the_model_arguments_given():
    ps = load_probe("ppo_settings")
    base = na.one_run(None, base="ppo")
    cfg = ps.config({"learning_rate": {"linear": [1.5e-3, 0.0]}, "n_epochs": 10})
    assert cfg.model == {
        **base.model,
        "learning_rate": {"linear": [1.5e-3, 0.0]},
        "n_epochs": 10,
    }
    assert cfg.env_kwargs == base.env_kwargs and cfg.restarts == 1
    assert cfg.restart_above is None


def test_ppo_settings_updates_the_policy_arguments_it_is_given_only():
    ps = load_probe("ppo_settings")
    base = na.one_run(None, base="sac")
    cfg = ps.config({}, "sac", {"log_std_min": -2.3})
    kwargs = {**base.model["policy_kwargs"], "log_std_min": -2.3}
    assert cfg.model == {**base.model, "policy_kwargs": kwargs}
    assert cfg.select == base.select and cfg.restarts == 1
