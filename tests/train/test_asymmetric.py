"""The asymmetric actor-critic of the PPO recipe (train.core.sb3_policies): the actor never
reads the privileged log(reward scale), the critic is exactly invariant to the scaling that
leaves V/c unchanged, the trained actor exports onto the plain env's observation, and the
recipe runs end to end on a tiny budget."""

from __future__ import annotations

import numpy as np
import pytest
import torch
import yaml

from train.core.sb3_policies import AsymmetricCriticPolicy


def _model():
    return _model_with()


def _model_with(**policy_kwargs):
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    venv = make_vec_env(
        "ACLDBeam-v1",
        n_envs=1,
        env_kwargs={
            "reward_scale": "passive",
            "observe_reward_scale": True,
            "episode_length": 0.05,
        },
    )
    return PPO(
        AsymmetricCriticPolicy,
        venv,
        n_steps=64,
        batch_size=64,
        seed=0,
        device="cpu",
        policy_kwargs={"net_arch": {"pi": [], "vf": []}, **policy_kwargs},
    )


def test_actor_ignores_log_scale_and_critic_is_scale_invariant():
    model = _model()
    pol = model.policy
    with torch.no_grad():  # make the critic's weights generic
        for p in pol.value_net.parameters():
            p.copy_(torch.randn_like(p))
    rng = np.random.default_rng(0)
    u = torch.as_tensor(rng.normal(size=(5, 9)), dtype=torch.float32)
    log_c = torch.as_tensor(rng.normal(size=(5, 1)), dtype=torch.float32)
    obs = torch.cat([u, log_c], dim=1)
    with torch.no_grad():
        a1 = pol._predict(obs, deterministic=True)
        a2 = pol._predict(torch.cat([u, log_c + 3.0], dim=1), deterministic=True)
        assert torch.equal(a1, a2)  # the actor never reads log c
        k = 7.0  # u -> sqrt(k) u with c -> k c: u / sqrt(c) and so the value are unchanged
        v1 = pol.predict_values(obs)
        v2 = pol.predict_values(torch.cat([u * np.sqrt(k), log_c + np.log(k)], dim=1))
        v3 = pol.predict_values(torch.cat([u * np.sqrt(k), log_c], dim=1))
    assert torch.allclose(v1, v2, rtol=1e-4, atol=1e-5)
    assert not torch.allclose(v1, v3, rtol=1e-2)


def test_recipe_trains_and_exports_onto_the_plain_observation():
    from train.benchmark import policy_program
    from train.config import TrainConfig
    from train.core.algos import train_algo

    data = yaml.safe_load(open("train/recipes/ppo.yaml"))
    assert data["env_kwargs"] == {
        "reward_scale": "passive",
        "observe_reward_scale": True,
        "observe_commands": True,  # appends nothing on v1 (no delay)
    }
    data.update(timesteps=2048, n_envs=4, whiten_steps=256, eval_points=1)
    data["model"] = {**data["model"], "n_steps": 128, "batch_size": 256, "n_epochs": 1}
    policy, record = train_algo(
        TrainConfig.from_dict(data), 0, "ACLDBeam-v1", lambda steps, pol: None
    )
    assert np.asarray(record["transform"]).shape == (9, 9)  # log c is not whitened
    assert policy.model.observation_space.shape == (10,)
    prog = policy_program(policy)
    z = np.random.default_rng(1).normal(size=(6, 9)).astype(np.float32)
    v, _ = policy.predict(z)  # on the plain env's 9 entries
    assert np.allclose(120 * prog(z.astype(np.float64)), v, atol=1e-3)


def test_env_kwargs_are_validated_by_the_env_config():
    from train.config import TrainConfig

    base = {"algo": "ppo", "timesteps": 10, "model": {"policy": "MlpPolicy"}}
    with pytest.raises(ValueError, match="env_kwargs: .*observe_reward_scale=True needs"):
        TrainConfig.from_dict({**base, "env_kwargs": {"observe_reward_scale": True}})
    with pytest.raises(ValueError, match="env_kwargs: unexpected keyword"):
        TrainConfig.from_dict({**base, "env_kwargs": {"reward_scael": "passive"}})


def _sac_config(**policy_kwargs):
    from train.config import TrainConfig

    data = yaml.safe_load(open("train/recipes/sac.yaml"))
    data.update(n_envs=2)
    model = data["model"]
    data["model"] = {
        **model,
        "buffer_size": 1000,
        "policy_kwargs": {**model["policy_kwargs"], **policy_kwargs},
    }
    return TrainConfig(**data)


def test_make_model_gives_the_sac_critic_the_configs_action_headroom():
    """The SAC critic reads the applied action, so it gets the env's action map: the
    config's ``action_headroom`` (3 in the recipe), once; a second, different value is
    refused by name."""
    from train.core.sb3_train import make_model, make_vec_env

    cfg = _sac_config()
    venv = make_vec_env(cfg, 0, "ACLDBeam-v1")
    try:
        model = make_model(cfg, venv, 0)
        assert cfg.action_headroom == 3.0 and model.policy.action_headroom == 3.0
        with pytest.raises(
            ValueError,
            match=r"model.policy_kwargs.action_headroom 2.0 "
            r"differs from action_headroom 3.0",
        ):
            make_model(_sac_config(action_headroom=2.0), venv, 0)
    finally:
        venv.close()


def test_drop_last_drops_n_privileged_entries_and_predict_pads_them():
    from gymnasium import spaces

    from train.core.sb3_policies import DropLast, SB3Policy

    box = spaces.Box(-np.inf, np.inf, (5,), np.float32)
    x = torch.arange(10.0).reshape(2, 5)
    assert torch.equal(DropLast(box)(x), x[:, :4])
    assert torch.equal(DropLast(box, n=2)(x), x[:, :3])
    for bad in (0, 5, 1.0):
        with pytest.raises(ValueError, match="n: expected an integer"):
            DropLast(box, n=bad)
    # an actor on 8 of the 10 entries (two privileged) predicts on the 8 alone
    model = _model_with(features_extractor_kwargs={"n": 2})
    assert model.policy.features_extractor.features_dim == 8
    z = np.random.default_rng(2).normal(size=(3, 8)).astype(np.float32)
    v, _ = SB3Policy(model, None, None).predict(z)
    with torch.no_grad():
        full = torch.as_tensor(np.concatenate([z, np.full((3, 2), 5.0, np.float32)], axis=1))
        a = model.policy._predict(full, deterministic=True).numpy()
    assert np.allclose(np.ravel(v), 120 * np.clip(a, -1, 1).ravel())  # the padding unread


def test_antithetic_noise_comes_in_pairs_and_needs_gsde(tmp_path):
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    from train.core.sb3_policies import SplitCriticPolicy

    venv = make_vec_env("ACLDBeam-v1", n_envs=4, env_kwargs={"episode_length": 0.05})
    kw = {"net_arch": {"pi": [], "vf": []}}
    model = PPO(
        SplitCriticPolicy,
        venv,
        n_steps=16,
        batch_size=64,
        use_sde=True,
        seed=0,
        device="cpu",
        policy_kwargs={**kw, "antithetic_noise": True},
    )
    pol = model.policy
    pol.reset_noise(4)
    e = pol.action_dist.exploration_matrices
    assert e.shape[0] == 4 and torch.equal(e[1::2], -e[0::2]) and not torch.equal(e[0], -e[2])
    obs = torch.as_tensor(np.repeat(venv.reset()[:1], 4, axis=0))
    with torch.no_grad():  # the same state: the pair's actions lie either side of the mean
        acts = pol(obs)[0]
        mean = pol._predict(obs, deterministic=True)
    assert torch.allclose(acts[0::2] - mean[0::2], mean[1::2] - acts[1::2], atol=1e-6)
    before = pol.action_dist.exploration_matrices.clone()
    with pytest.raises(ValueError, match="1 or an even number of noise draws.*got 3"):
        pol.reset_noise(3)
    assert torch.equal(pol.action_dist.exploration_matrices, before)  # left as it was
    pol.reset_noise(1)  # one draw has no pair: gSDE's own (SB3's load makes this call)
    assert pol.action_dist.exploration_matrices.shape[0] == 1
    assert pol._get_constructor_parameters()["antithetic_noise"] is True
    model.save(tmp_path / "anti.zip")  # rl-zoo3 and SB3 users load such a model
    loaded = PPO.load(tmp_path / "anti.zip", device="cpu")
    assert loaded.policy.antithetic_noise is True
    with torch.no_grad():
        assert torch.equal(loaded.policy._predict(obs, deterministic=True), mean)
    plain = PPO(SplitCriticPolicy, venv, n_steps=16, use_sde=True, seed=0, device="cpu")
    plain.policy.reset_noise(4)  # default: independent noise per sub-env
    e = plain.policy.action_dist.exploration_matrices
    assert not torch.allclose(e[1::2], -e[0::2])
    for bad, sde in ((True, False), ("yes", True)):
        with pytest.raises(ValueError, match="antithetic_noise must be"):
            PPO(
                SplitCriticPolicy,
                venv,
                use_sde=sde,
                device="cpu",
                policy_kwargs={**kw, "antithetic_noise": bad},
            )


def test_the_negative_critic_is_never_positive_scale_invariant_and_trains_through_m():
    """``critic_features: negative_scaled_quadratic``: V = -||M [u / sqrt(c); 1]||^2 is at
    most 0 for every observation, up to the limit cycle's sizes; invariant to the load's
    scale as the recipe's critic is; M takes the gradient, the fixed output layer none; it
    takes no hidden critic layers."""
    model = _model_with(critic_features="negative_scaled_quadratic")
    pol = model.policy
    rng = np.random.default_rng(0)
    u = rng.normal(size=(64, 9)) * 10.0 ** rng.uniform(-3, 6, (64, 1))
    obs = torch.as_tensor(np.c_[u, rng.uniform(-20, 20, 64)], dtype=torch.float32)
    k = 5.0
    scaled = torch.cat([obs[:, :9] * np.sqrt(k), obs[:, 9:] + np.log(k)], dim=1)
    with torch.no_grad():
        pol.vf_features_extractor.m.copy_(torch.randn_like(pol.vf_features_extractor.m))
        v = pol.predict_values(obs)
        assert torch.all(v <= 0) and torch.allclose(pol.predict_values(scaled), v, rtol=1e-4)
    trainable = {n for n, p in pol.named_parameters() if p.requires_grad}
    assert "vf_features_extractor.m" in trainable
    assert not {"value_net.weight", "value_net.bias"} & trainable
    assert float(pol.value_net.weight) == -1.0 and float(pol.value_net.bias) == 0.0
    pol.predict_values(obs[:4]).sum().backward()
    assert pol.vf_features_extractor.m.grad.abs().sum() > 0
    with pytest.raises(ValueError, match="negative_scaled_quadratic.*vf: \\[\\]"):
        _model_with(critic_features="negative_scaled_quadratic", net_arch={"pi": [], "vf": [8]})


def test_the_negative_critic_saves_and_loads_fixed(tmp_path):
    from stable_baselines3 import PPO

    model = _model_with(critic_features="negative_scaled_quadratic")
    model.learn(64)
    model.save(tmp_path / "m.zip")
    back = PPO.load(tmp_path / "m.zip", device="cpu")
    obs = torch.as_tensor(np.random.default_rng(1).normal(size=(3, 10)), dtype=torch.float32)
    with torch.no_grad():
        assert torch.equal(back.policy.predict_values(obs), model.policy.predict_values(obs))
    assert not back.policy.value_net.weight.requires_grad


def test_the_sac_negative_critic_is_never_positive_and_saves(tmp_path):
    """``negative_critic`` (SAC): each twin critic is Q = -||M [w; s]||^2, w = [u, clip(3 a)]
    / sqrt(c), s the offset scale (100), computed here by hand: at most 0 for every
    observation and action, trained through M alone; it takes no hidden layers; SAC.load
    gives the same critic back."""
    from stable_baselines3 import SAC

    from train.core.sb3_policies import NegativeSquareForm
    from train.core.sb3_train import make_model, make_vec_env

    cfg = _sac_config(negative_critic=True)
    venv = make_vec_env(cfg, 0, "ACLDBeam-v1")
    try:
        model = make_model(cfg, venv, 0)
        critic = model.critic
        assert all(isinstance(q, NegativeSquareForm) for q in critic.q_networks)
        assert {n for n, _ in critic.named_parameters()} == {"qf0.m", "qf1.m"}
        rng = np.random.default_rng(0)
        u = rng.normal(size=(64, 9)) * 10.0 ** rng.uniform(-3, 6, (64, 1))
        log_c = rng.uniform(-20, 20, (64, 1))
        a = rng.uniform(-1, 1, (64, 1))
        obs = torch.as_tensor(np.c_[u, log_c], dtype=torch.float32)
        act = torch.as_tensor(a, dtype=torch.float32)
        z = np.c_[u, np.clip(3.0 * a, -1, 1)] * np.exp(-0.5 * log_c)
        z = np.c_[z, np.full(64, 100.0)]
        with torch.no_grad():
            for q in critic.q_networks:
                q.m.copy_(torch.randn_like(q.m))
            q1, q2 = critic(obs, act)
            assert torch.all(q1 <= 0) and torch.all(q2 <= 0) and not torch.equal(q1, q2)
            m = critic.q_networks[0].m.double().numpy()
            by_hand = -(((z @ m.T) ** 2).sum(axis=1))
            np.testing.assert_allclose(q1.double().numpy()[:, 0], by_hand, rtol=1e-4)
        critic.q1_forward(obs[:4], act[:4]).sum().backward()
        assert critic.q_networks[0].m.grad.abs().sum() > 0
        model.learn(200)
        model.save(tmp_path / "sac.zip")
        back = SAC.load(tmp_path / "sac.zip", device="cpu")
        with torch.no_grad():
            assert torch.equal(back.critic(obs, act)[0], model.critic(obs, act)[0])
        assert back.policy.negative_critic is True
        with pytest.raises(
            ValueError,
            match=r"negative \(SAC's policy_kwargs negative_critic\) must be .* qf: \[8\]",
        ):
            make_model(_sac_config(negative_critic=True, net_arch={"pi": [], "qf": [8]}), venv, 0)
        with pytest.raises(ValueError, match="negative_critic\\) must be true or false.*'yes'"):
            make_model(_sac_config(negative_critic="yes"), venv, 0)
    finally:
        venv.close()
