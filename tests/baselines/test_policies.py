"""Reference policies and the clairvoyant bound (baselines/), through ACLDBeam-v1.

The bound and the ratios run on the default (converged) plant; the acceptance against
the thesis's Table 2 runs on ``mesh="thesis"``, the thesis's own model.
"""

import numpy as np
import pytest

from acld_gym.design.nominal import nominal_design
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.physics.loads import thesis_load
from acld_gym.thesis.metrics import peak, settling_time
from acld_gym.thesis.table2 import thesis_row
from baselines.bound import clairvoyant_bound
from baselines.policies import LQRPolicy, MPCPolicy, PassivePolicy, RewardMPCPolicy, SMCPolicy

SENSOR = 1e-7  # tip-sensor noise [m], the env default


def rollout(policy, case, seed=0, mesh="converged"):
    env = ACLDBeamEnv(load_case=case, sensor_noise=SENSOR, mesh=mesh)
    obs, _ = env.reset(seed=seed)
    ys, vs = [], []
    done = False
    while not done:
        a, _ = policy.predict(obs, deterministic=True)
        obs, _, term, trunc, info = env.step(a)
        ys.append(info["tip_deflection"])
        vs.append(info["voltage"])
        done = term or trunc
    return np.array(ys), np.array(vs)


@pytest.fixture(scope="module")
def results():
    nom = nominal_design()
    pols = {"passive": PassivePolicy(), "lqr": LQRPolicy(), "smc": SMCPolicy(), "mpc": MPCPolicy()}
    out = {}
    for case in (1, 2, 3):
        b = clairvoyant_bound(nom.plant, nom.output, thesis_load(case), 1000)
        out[case, "bound"] = (b.y, b.voltage)
        for name, p in pols.items():
            out[case, name] = rollout(p, case)
    return out


@pytest.fixture(scope="module")
def thesis_results():
    pols = {"lqr": LQRPolicy(mesh="thesis"), "smc": SMCPolicy(mesh="thesis")}
    return {
        (case, name): rollout(p, case, mesh="thesis")
        for case in (1, 2, 3)
        for name, p in pols.items()
    }


def ise(y):
    return float(np.sum(y**2) * 1e-3)


@pytest.mark.parametrize("case", [1, 2, 3])
def test_bound_is_below_every_policy(results, case):
    # No causal policy can beat the clairvoyant optimum on the same episode.
    b = ise(results[case, "bound"][0])
    for name in ("passive", "lqr", "smc", "mpc"):
        assert b <= ise(results[case, name][0]) * (1 + 1e-9), name
    assert np.all(np.abs(results[case, "bound"][1]) <= 120.0 + 1e-9)


@pytest.mark.parametrize("case, lqr_ratio", [(1, 1.25), (2, 1.35), (3, 1.02)])
def test_mpc_within_1p25_of_bound_and_lqr_ratios(results, case, lqr_ratio):
    # Measured on ACLDBeam-v1 (python -m baselines.evaluate, docs/baselines.md): MPC 1.18x, 1.24x,
    # 1.01x of the bound; LQR 1.25x, 1.35x, 1.02x. 8 % tolerance: the switching
    # controllers make the ratios move with the noise realization by a few percent.
    b = ise(results[case, "bound"][0])
    assert ise(results[case, "mpc"][0]) / b < 1.25
    assert ise(results[case, "mpc"][0]) < ise(results[case, "lqr"][0])
    assert ise(results[case, "lqr"][0]) / b == pytest.approx(lqr_ratio, rel=0.08)


@pytest.mark.parametrize("case", [1, 2, 3])
@pytest.mark.parametrize("name", ["lqr", "smc"])
def test_through_env_matches_thesis_saturated_rows(thesis_results, case, name):
    # Thesis Table 2, saturated rows, on the thesis's mesh: peak within 7 %, settling
    # within 10 % (discrete LQR/SMC at 1 kHz with the Kalman observer, docs/baselines.md).
    y, v = thesis_results[case, name]
    t = np.arange(1, y.size + 1) * 1e-3
    ref = thesis_row(case, name, True)
    assert peak(y) * 1e3 == pytest.approx(ref.peak_mm, rel=0.07)
    assert settling_time(t, y) == pytest.approx(ref.settling_s, rel=0.10)
    assert np.max(np.abs(v)) <= 120.0


def test_predict_protocol_single_and_batched():
    pol = LQRPolicy()
    env = ACLDBeamEnv()
    obs, _ = env.reset(seed=0)
    a, state = pol.predict(obs)
    assert a.shape == (1,) and a.dtype == np.float32 and state is None
    batch = np.stack([obs, 2 * obs, -obs])
    ab, _ = pol.predict(batch, episode_start=np.ones(3, bool))
    assert ab.shape == (3, 1)
    np.testing.assert_allclose(ab[0], a)
    assert np.all(np.abs(ab) <= 120.0)


def test_smc_sliding_dynamics_stable_and_switching_sign():
    # Zero dynamics of the sampled surface must be stable; sign(s B) c > 0 gives
    # sigma_{k+1} = -|s B| c sat(.) + ... (reaching condition).
    pol = SMCPolicy()
    sr = pol.nom.reduced
    B = sr.Bd[:, 0]
    Acl = sr.Ad - np.outer(B, pol.s @ sr.Ad) / pol.sb
    assert np.max(np.abs(np.linalg.eigvals(Acl))) < 1.0
    assert pol.sb * pol.c > 0


def test_predict_rejects_wrong_observation():
    with pytest.raises(ValueError, match="obs"):
        LQRPolicy().predict(np.zeros(7, np.float32))


def test_sb3_evaluate_policy_accepts_baselines():
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.monitor import Monitor

    env = Monitor(ACLDBeamEnv(load_case=1, sensor_noise=SENSOR))
    mean, _ = evaluate_policy(LQRPolicy(), env, n_eval_episodes=1)
    mean_p, _ = evaluate_policy(PassivePolicy(), env, n_eval_episodes=1)
    assert mean > mean_p  # LQR earns more reward than doing nothing


def test_bad_arguments():
    nom = nominal_design()
    with pytest.raises(ValueError, match="eps"):
        SMCPolicy(eps=0.0)
    with pytest.raises(ValueError, match="horizon"):
        MPCPolicy(horizon=0)
    with pytest.raises(ValueError, match="n_steps"):
        clairvoyant_bound(nom.plant, nom.output, thesis_load(1), 0)
    with pytest.raises(ValueError, match="state_weight"):
        MPCPolicy(state_weight=-1.0)
    with pytest.raises(ValueError, match="lam"):
        RewardMPCPolicy(lam=-0.01)
    with pytest.raises(ValueError, match="y_ref"):
        RewardMPCPolicy(y_ref=0.0)


def test_reward_mpc_is_the_mpc_of_the_env_reward():
    # The env's step cost (y / y_ref)^2 + lam (V / 120)^2 is the MPC's (y / 1 mm)^2 +
    # rho (V / 120)^2 times (1 mm / y_ref)^2, so rho = lam (y_ref / 1 mm)^2: a reward
    # scaled as a whole (y_ref doubled, lam quartered) leaves the law as it is, and the
    # default env's law is the plain MPC at rho = lam without the state weight.
    nom = nominal_design()
    base = RewardMPCPolicy.for_env(ACLDBeamEnv()).small_signal_gain()
    plain = MPCPolicy(nom=nom, rho=0.01, state_weight=0.0).small_signal_gain()
    np.testing.assert_allclose(base, plain, rtol=1e-12)
    scaled = RewardMPCPolicy.for_env(ACLDBeamEnv(y_ref=2e-3, lam=0.0025)).small_signal_gain()
    np.testing.assert_allclose(scaled, base, rtol=1e-9)
    dearer = RewardMPCPolicy.for_env(ACLDBeamEnv(y_ref=2e-3, lam=0.01)).small_signal_gain()
    assert np.linalg.norm(dearer) < 0.9 * np.linalg.norm(base)  # rho 0.04: a softer law


@pytest.mark.parametrize("case", [1, 2, 3])
def test_reward_mpc_earns_more_of_the_env_reward_than_the_designed_laws(case):
    # The law built for the env's own objective earns more of it on each thesis case than
    # LQR, SMC and the robust MPC, which are designed on other costs (measured: -15.1
    # against -16.9 to -17.2 on case 1, -40.0 against -42.5 to -45.4 on case 2, -3087.6
    # against -3097.8 to -3116.2 on case 3).
    from baselines.evaluate import rollout as eval_rollout

    env = ACLDBeamEnv(load_case=case, sensor_noise=SENSOR)
    ret = {
        p.name: float(np.sum(eval_rollout(p, env, seed=0).reward))
        for p in (LQRPolicy(), SMCPolicy(), MPCPolicy(), RewardMPCPolicy())
    }
    best_designed = max(ret["lqr"], ret["smc"], ret["mpc"])
    assert ret["mpc_reward"] > best_designed + 0.002 * abs(best_designed), ret


def test_policies_refuse_an_env_of_another_design():
    # A policy decodes the observation with its design; the evaluator checks the
    # fingerprint before the first step (acld_gym.envs.fingerprint).
    from baselines.evaluate import rollout as eval_rollout

    with pytest.raises(ValueError, match="mesh"):
        eval_rollout(LQRPolicy(mesh="thesis"), ACLDBeamEnv(mesh="converged"))
    ep = eval_rollout(LQRPolicy.for_env(ACLDBeamEnv(mesh="thesis")), ACLDBeamEnv(mesh="thesis"))
    assert ep.y.size == 1000
