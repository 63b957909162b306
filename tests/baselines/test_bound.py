"""The clairvoyant bound's solvers (baselines/bound.py): the structured, certified
active-set solver against BVLS, and the pieces it is built from."""

import warnings

import numpy as np
import pytest

from acld_gym.design.nominal import nominal_design
from acld_gym.physics.loads import TipLoad, random_load, thesis_load
from baselines import bound
from baselines.bound import (
    ATOL,
    RTOL,
    clairvoyant_bound,
    convolution_matrix,
    free_response,
    impulse_response,
    kkt_check,
    reversed_gram,
)

N = 1000


def plant_and_tip():
    """The nominal plant and its tip output: the output row where the model has one, else
    the tip's state index."""
    nom = nominal_design()
    tip = getattr(nom, "output", None)
    return nom.plant, (nom.design.model.tip_index if tip is None else tip)


def episode_load(which):
    plant, _ = plant_and_tip()
    if isinstance(which, int):
        return thesis_load(which)
    return random_load(np.random.default_rng(which[1]), N * plant.dt, plant.dt / plant.substeps)


def certified_bound(load, n=N):
    """The default solver's bound, failing on a fallback to BVLS."""
    plant, tip = plant_and_tip()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        return clairvoyant_bound(plant, tip, load, n)


def stepwise_free_response(plant, c, load, n):
    """The free response the way the environment steps it (the reference)."""
    x = np.zeros(plant.Ad.shape[0])
    y = np.empty(n)
    for k in range(n):
        f0, f1 = plant.load_samples(load, k * plant.dt)
        x = plant.Ad @ x + plant.load_increment(f0, f1)
        y[k] = c @ x
    return y


def output_row(tip, nx):
    if isinstance(tip, (int, np.integer)):
        return np.eye(nx)[tip]
    return np.asarray(tip, dtype=float)


@pytest.mark.parametrize("which", [1, ("random", 0)], ids=["thesis1", "random0"])
def test_kkt_conditions_hold_and_voltages_in_box(which):
    plant, tip = plant_and_tip()
    load = episode_load(which)
    sol = certified_bound(load)
    assert np.all(np.abs(sol.voltage) <= 120.0)
    # Independent check on the dense problem, in the solvers' units (mm, units of 120 V).
    h = impulse_response(plant, tip, N) * (120.0 / 1e-3)
    G = convolution_matrix(h)
    y_free = free_response(plant, tip, load, N)
    v = sol.voltage / 120.0
    r = y_free / 1e-3 + G @ v
    np.testing.assert_allclose(sol.y / 1e-3, r, rtol=0, atol=1e-9 * np.abs(r).max())
    g = G.T @ r
    tol = 1e-6 * np.linalg.norm(h) * np.linalg.norm(r)  # |g_j| <= ||h|| ||r|| for any j
    at_lo, at_hi = v <= -1 + 1e-12, v >= 1 - 1e-12
    assert np.all(g[at_lo] >= -tol)
    assert np.all(g[at_hi] <= tol)
    assert np.all(np.abs(g[~(at_lo | at_hi)]) <= tol)
    # The certificate: the duality gap bounds the excess cost over the optimum.
    gap = np.sum(g * v + np.abs(g))
    y_s = y_free / 1e-3
    assert 0 <= gap <= RTOL * 0.5 * (r @ r) + ATOL * 0.5 * (y_s @ y_s)
    chk = kkt_check(impulse_response(plant, tip, N), y_free, sol.voltage)
    assert chk.certifies()
    assert chk.gap == pytest.approx(gap, rel=1e-6, abs=1e-12 * (r @ r))


@pytest.mark.slow
@pytest.mark.parametrize(
    "which",
    [1, 2, 3] + [("random", s) for s in range(5)],
    ids=[f"thesis{c}" for c in (1, 2, 3)] + [f"random{s}" for s in range(5)],
)
def test_ise_equals_bvls(which):
    plant, tip = plant_and_tip()
    load = episode_load(which)
    new = certified_bound(load)
    ref = clairvoyant_bound(plant, tip, load, N, method="bvls")
    assert new.ise == pytest.approx(ref.ise, rel=1e-6)


@pytest.mark.parametrize("n", [1, 2, 40, 150])
def test_short_episodes_match_bvls(n):
    plant, tip = plant_and_tip()
    load = thesis_load(2)
    new = certified_bound(load, n)
    ref = clairvoyant_bound(plant, tip, load, n, method="bvls")
    assert new.voltage.shape == new.y.shape == (n,)
    assert new.ise == pytest.approx(ref.ise, rel=1e-6, abs=1e-30)


def test_zero_load_needs_no_voltage():
    sol = certified_bound(TipLoad(()), 200)
    assert np.all(sol.voltage == 0) and np.all(sol.y == 0) and sol.ise == 0


def test_uncertified_result_falls_back_to_bvls(monkeypatch):
    plant, tip = plant_and_tip()
    load = thesis_load(2)
    ref = clairvoyant_bound(plant, tip, load, 150, method="bvls")
    solve = bound._solve_pdas
    monkeypatch.setattr(bound, "_solve_pdas", lambda h, y: solve(h, y, max_iter=1, max_stages=1))
    with pytest.warns(RuntimeWarning, match="BVLS"):
        sol = clairvoyant_bound(plant, tip, load, 150)
    np.testing.assert_allclose(sol.voltage, ref.voltage)


def test_free_and_impulse_responses_match_stepping():
    plant, tip = plant_and_tip()
    c = output_row(tip, plant.Ad.shape[0])
    for load in (thesis_load(2), episode_load(("random", 3))):
        ref = stepwise_free_response(plant, c, load, 300)
        y = free_response(plant, tip, load, 300)
        np.testing.assert_allclose(y, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
    xb, h_ref = plant.Bd[:, 0].copy(), np.empty(300)
    for k in range(300):
        h_ref[k] = c @ xb
        xb = plant.Ad @ xb
    for system, out in ((plant, tip), ((plant.Ad, plant.Bd), c), ((plant.Ad, plant.Bd[:, 0]), c)):
        np.testing.assert_allclose(
            impulse_response(system, out, 300), h_ref, rtol=0, atol=1e-10 * np.abs(h_ref).max()
        )


@pytest.mark.parametrize("n", [1, 2, 7, 64])
def test_reversed_gram_is_flipped_gram(n):
    h = np.random.default_rng(n).normal(size=n)
    G = convolution_matrix(h)
    np.testing.assert_allclose(reversed_gram(h), (G.T @ G)[::-1, ::-1], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(G, np.tril(G))
    np.testing.assert_array_equal(G[:, 0], h)


def test_bad_input_names_the_argument():
    plant, tip = plant_and_tip()
    load = thesis_load(1)
    for n in (0, -3, 2.5, True):
        with pytest.raises(ValueError, match="n_steps"):
            clairvoyant_bound(plant, tip, load, n)
    with pytest.raises(ValueError, match="method"):
        clairvoyant_bound(plant, tip, load, 10, method="osqp")
    with pytest.raises(ValueError, match="n"):
        impulse_response(plant, tip, 0)
    with pytest.raises(ValueError, match="output"):
        impulse_response(plant, plant.Ad.shape[0], 10)
    with pytest.raises(ValueError, match="output"):
        impulse_response(plant, np.ones(3), 10)


# --- the bound of each actuator option (issue 21) ------------------------------------------
OPTIONS = {
    "delay": dict(actuator_delay=2),
    "lag": dict(amplifier_bandwidth=300.0),
    "slew": dict(slew_rate=2e4),
    "all": dict(actuator_delay=1, amplifier_bandwidth=500.0, slew_rate=3e4, temperature=23.0),
}


@pytest.mark.parametrize("name", list(OPTIONS))
def test_with_each_option_the_bound_is_below_every_policy_and_certified(name):
    import warnings

    from acld_gym.envs.beam_env import ACLDBeamEnv
    from baselines.evaluate import bound_episode, default_policies, metrics_row, rollout

    env = ACLDBeamEnv(load_case=2, episode_length=0.3, **OPTIONS[name])
    policies = {key: type(p).for_env(env) for key, p in default_policies().items()}
    ise = {key: metrics_row(2, key, rollout(p, env, seed=0)).ise for key, p in policies.items()}
    env.reset(seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an uncertified solution warns
        ep = bound_episode(env)
    bound = metrics_row(2, "bound", ep).ise
    assert all(bound < v for v in ise.values()), (bound, ise)
    # the bound's voltages are feasible for this actuator
    assert np.all(np.abs(ep.voltage) <= 120.0 + 1e-9)
    if "actuator_delay" in OPTIONS[name]:
        assert np.all(ep.voltage[: OPTIONS[name]["actuator_delay"]] == 0.0)


def test_slew_certificate_is_a_lower_bound_of_every_feasible_point():
    from baselines.bound import slew_certificate
    from baselines.bound_slew import _feasible, _solve_slew

    nom = nominal_design()
    n, rho = 80, 0.1
    h = impulse_response(nom.plant, nom.output, n) * 120 / 1e-3
    y = free_response(nom.plant, nom.output, thesis_load(1), n) / 1e-3
    w, cert = _solve_slew(h, y, rho)
    assert cert.feasible and cert.lower <= cert.objective and cert.certifies()
    rng = np.random.default_rng(0)
    for _ in range(200):  # any feasible sequence costs at least the certified lower bound
        u = _feasible(w + rng.normal(0.0, 0.3, n), rho)
        assert slew_certificate(h, y, u, np.zeros(n), rho).objective >= cert.lower
    # a wrong multiplier still gives a valid (looser) lower bound
    loose = slew_certificate(h, y, w, rng.normal(0.0, 1.0, n), rho)
    assert loose.lower <= cert.objective
    # the slew limit binds: without it the optimum is lower
    free = clairvoyant_bound(nom.plant, nom.output, thesis_load(1), n)
    assert np.sum(free.y**2) < np.sum((y + np.convolve(h, w)[:n]) ** 2) * 1e-6
    assert np.abs(np.diff(np.r_[0.0, w])).max() == pytest.approx(rho)
