"""train.vec: the action map, the shaping potential and the wrapped training env."""

import numpy as np
import pytest
import scipy.linalg as sla

from acld_gym.design.nominal import nominal_design
from baselines.policies import LQRPolicy
from train.config import load_config
from train.vec import (
    ConcatVecEnv,
    VecAgentEnv,
    VoltageMap,
    find_wrapper,
    lq_potential,
    make_vec_env,
)


def test_voltage_map_plain_and_residual():
    obs = np.random.default_rng(0).normal(size=(5, 9))
    a = np.array([[-1.0], [-0.5], [0.0], [0.5], [2.0]])
    assert np.allclose(VoltageMap()(a, obs)[:, 0], [-120, -60, 0, 60, 120])  # 2.0 -> clipped
    lqr = LQRPolicy()
    u0 = lqr.voltage(lqr.reduced_state(obs))
    res = VoltageMap("lqr")
    # zero residual = the (saturated) LQR voltage
    assert np.allclose(res(np.zeros((5, 1)), obs)[:, 0], np.clip(u0, -120, 120), atol=1e-3)
    # a residual moves the unsaturated LQR voltage by at most 240 V
    for r in (-1.0, -0.3, 0.4, 1.0):
        expect = np.clip(u0 + 240.0 * r, -120, 120)
        assert np.allclose(res(np.full((5, 1), r), obs)[:, 0], expect, atol=1e-3)
    with pytest.raises(ValueError, match="residual"):
        VoltageMap("pid")


def test_voltage_map_headroom_is_the_wrappers_map():
    """``headroom`` k: V = 120 clip(k a), the map of acld_gym.wrappers.UnitAction (whose env
    clips); k = 1 is the plain map bit for bit; with the LQR residual the action moves the
    LQR voltage by 240 k a."""
    from acld_gym.envs.beam_env import ACLDBeamEnv
    from acld_gym.wrappers import UnitAction

    rng = np.random.default_rng(1)
    obs = rng.normal(size=(7, 9))
    a = np.array([[-1.5], [-0.4], [-0.2], [0.0], [0.1], [1 / 3], [1.0]])
    v = VoltageMap(headroom=3.0)(a, obs)[:, 0]
    assert np.allclose(v, [-120, -120, -72, 0, 36, 120, 120])
    unit = UnitAction(ACLDBeamEnv(load_case=1), headroom=3.0)
    assert np.allclose(v, np.clip(unit.action(a[:, 0]), -120, 120))
    a1 = rng.uniform(-2, 2, (50, 1))
    assert np.array_equal(
        VoltageMap(headroom=1.0)(a1, obs[:1].repeat(50, 0)), VoltageMap()(a1, obs[:1].repeat(50, 0))
    )
    lqr = LQRPolicy()
    u0 = lqr.voltage(lqr.reduced_state(obs))
    res = VoltageMap("lqr", headroom=2.0)
    assert np.allclose(
        res(np.full((7, 1), 0.1), obs)[:, 0], np.clip(u0 + 48.0, -120, 120), atol=1e-3
    )
    with pytest.raises(ValueError, match="headroom must be a number"):
        VoltageMap(headroom=0.9)


def test_lq_potential_solves_the_discounted_riccati_equation():
    gamma, lam = 0.99, 0.01
    P = lq_potential(gamma, lam)
    assert np.allclose(P, P.T, rtol=1e-8, atol=1e-10 * np.abs(P).max())
    assert np.linalg.eigvalsh(P).min() > 0  # positive definite (observable output)
    nom = nominal_design()
    S = np.diag(nom.xr_scale)
    A = np.sqrt(gamma) * np.linalg.solve(S, nom.reduced.Ad @ S)
    B = np.sqrt(gamma) * np.linalg.solve(S, nom.reduced.Bd)
    Q = S @ nom.design.reduced.C.T @ nom.design.reduced.C @ S / 1e-6
    R = lam / 120.0**2
    # the DARE residual, relative to P's size
    K = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)
    res = A.T @ P @ A - P + Q - A.T @ P @ B @ K
    assert np.abs(res).max() < 1e-8 * np.abs(P).max()
    # more expensive voltage -> larger cost-to-go
    assert np.all(np.linalg.eigvalsh(lq_potential(gamma, 1.0) - P) > -1e-9 * np.abs(P).max())
    assert sla.norm(lq_potential(0.9, lam)) < sla.norm(P)  # shorter horizon, smaller value


def test_shaping_is_potential_based():
    """Shaped minus raw reward is gamma Phi(s') - Phi(s) step by step (terminal obs at the end)."""
    cfg = load_config("ppo").with_overrides(n_envs=2, loads={1: 1}, shaping=0.01)
    raw = VecAgentEnv(_base(cfg), None, cfg.gamma, None)
    shaped = VecAgentEnv(_base(cfg), None, cfg.gamma, cfg.shaping)
    o_raw, o_sh = raw.reset(), shaped.reset()
    assert np.array_equal(o_raw, o_sh)
    acts = np.random.default_rng(1).uniform(-1, 1, (1000, 2, 1)).astype(np.float32)
    prev = o_sh
    for k in range(1000):
        for v in (raw, shaped):
            v.step_async(acts[k])
        o1, r1, d1, i1 = raw.step_wait()
        o2, r2, d2, i2 = shaped.step_wait()
        assert np.array_equal(o1, o2) and np.array_equal(d1, d2)
        nxt = o2.copy()
        for i in np.flatnonzero(d2):
            nxt[i] = i2[i]["terminal_observation"]
        expect = r1 + cfg.gamma * shaped.potential(nxt) - shaped.potential(prev)
        assert np.allclose(r2, expect, rtol=1e-5, atol=1e-5)
        prev = o2
    assert d2.all()  # the episode ended (1000 steps) inside the loop


def _base(cfg):
    from acld_gym.envs.sb3 import SB3VecEnv

    v = SB3VecEnv(num_envs=cfg.n_envs, load_case=1)
    v.seed(3)
    return v


def test_make_vec_env_is_seeded_and_normalized():
    cfg = load_config("ppo_dagger").with_overrides(n_envs=3)
    a, b = make_vec_env(cfg, seed=5), make_vec_env(cfg, seed=5)
    oa, ob = a.reset(), b.reset()
    assert np.array_equal(oa, ob) and oa.shape == (3, 10)  # direction features of the 9
    assert a.action_space.low[0] == -1 and a.action_space.high[0] == 1
    act = np.full((3, 1), 0.3, np.float32)
    for _ in range(20):
        a.step_async(act)
        b.step_async(act)
        ra, rb = a.step_wait(), b.step_wait()
    assert np.array_equal(ra[0], rb[0]) and np.array_equal(ra[1], rb[1])
    assert find_wrapper(a, VecAgentEnv).P is not None  # the config's shaping
    with pytest.raises(ValueError, match="backend"):
        make_vec_env(cfg, 0, backend="ray")


def test_make_vec_env_splits_the_loads_and_passes_env_options():
    """Sub-envs per load in proportion to the weights, each with the config's env options
    (here the recipe's reward scale, observed as the last entry)."""
    # the PPO recipe with the sub-envs on their own seeds (no pairs), so any split
    cfg = load_config("ppo").with_overrides(n_envs=4, loads={1: 1, "random": 3}, paired_loads=False)
    venv = make_vec_env(cfg, seed=0)
    obs = venv.reset()
    assert obs.shape == (4, 10)  # 9 + log c (observe_reward_scale)
    inner = find_wrapper(venv, ConcatVecEnv)
    assert [v.num_envs for v in inner.venvs] == [1, 3]
    assert inner.get_attr("load_case") == [1, "random", "random", "random"]
    venv.step_async(np.zeros((4, 1), np.float32))
    _, _, _, infos = venv.step_wait()
    assert all("reward_scale" in i for i in infos)


def test_subproc_backend_is_the_same_env():
    cfg = load_config("ppo").with_overrides(n_envs=2, loads={1: 1}, paired_loads=False)
    native, sub = make_vec_env(cfg, seed=4), make_vec_env(cfg, seed=4, backend="subproc")
    try:
        on, os_ = native.reset(), sub.reset()
        assert np.allclose(on, os_, rtol=1e-6, atol=1e-7)
        act = np.full((2, 1), -0.2, np.float32)
        for _ in range(5):
            rn, rs = native.step(act), sub.step(act)
        assert np.allclose(rn[0], rs[0], rtol=1e-5, atol=1e-6)
        assert np.allclose(rn[1], rs[1], rtol=1e-5, atol=1e-12)
    finally:
        native.close()
        sub.close()


def test_make_vec_env_pairs_the_sub_envs_with_paired_loads():
    """``paired_loads``: sub-envs 2i and 2i+1 of each load case run the same episodes under
    the same actions; with the subprocess backend it is refused."""
    cfg = load_config("ppo").with_overrides(n_envs=6, loads={1: 1, "random": 2})
    assert cfg.paired_loads  # the recipe's, since acld-gym 0.15.0
    venv = make_vec_env(cfg, seed=3)
    obs = venv.reset()
    assert obs.shape == (6, 10)
    act = np.repeat(np.random.default_rng(1).uniform(-1, 1, (3, 1)), 2, axis=0)
    for _ in range(30):
        obs, rew, _, _ = venv.step(act.astype(np.float32))
    np.testing.assert_array_equal(obs[0::2], obs[1::2])
    np.testing.assert_array_equal(rew[0::2], rew[1::2])
    assert not np.array_equal(obs[2], obs[4])  # the random pairs differ from each other
    with pytest.raises(ValueError, match="paired_loads needs backend 'native'"):
        make_vec_env(cfg, 0, backend="subproc")
