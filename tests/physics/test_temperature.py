"""Temperature of the viscoelastic layer (issue 21): time-temperature superposition of the
GHM modulus with a WLF shift, checked as physics, and the env's temperature options."""

from __future__ import annotations

import numpy as np
import pytest

from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.episode import fixed_plant
from acld_gym.physics.model import oscillatory_modes
from acld_gym.physics.temperature import (
    LOSS_PEAK_HZ,
    T_GLASS,
    T_REF,
    TEMPERATURE_RANGE,
    WLF_C1,
    WLF_C2,
    ghm_modulus,
    log_shift,
    shift_factor,
    shifted_parameters,
)
from acld_gym.physics.truth import plant

GRID = np.linspace(*TEMPERATURE_RANGE, 31)


def test_shift_is_wlf_about_the_glass_transition():
    assert log_shift(T_REF) == 0.0 and shift_factor(T_REF) == 1.0
    for T in (17.0, 25.0, 33.0):

        def wlf(t):
            return -WLF_C1 * (t - T_GLASS) / (WLF_C2 + t - T_GLASS)

        assert log_shift(T) == pytest.approx(wlf(T) - wlf(T_REF), rel=1e-12)
    assert np.all(np.diff([log_shift(T) for T in GRID]) < 0)  # hotter: faster relaxation
    # at T_g the thesis material's loss peak sits at 1 Hz (the convention that fixes T_g)
    assert LOSS_PEAK_HZ / shift_factor(T_GLASS) == pytest.approx(1.0, rel=1e-9)


def test_superposition_shifts_the_modulus_along_frequency():
    p = plant("thesis").params
    w = np.logspace(0, 4, 9)
    for T in (17.0, 27.0):
        # G(j w, T) = G_ref(j a_T w): the same curve at the reduced frequency
        np.testing.assert_allclose(
            ghm_modulus(shifted_parameters(p, T), w),
            ghm_modulus(p, shift_factor(T) * w),
            rtol=1e-12,
        )
    assert shifted_parameters(p, T_REF) is p


def _mode1(params):
    """The first bending mode of the converged beam (an eigenvalue near 177 rad/s; the GHM
    coordinates add slow modes of their own at low temperature)."""
    lam = oscillatory_modes(plant("converged").state_space(params)[0])
    return lam[np.argmin(np.abs(lam.imag - 177.0))]


def test_hotter_is_softer_and_the_loss_peaks_in_the_transition():
    p = plant("converged").params
    modes = np.array([_mode1(shifted_parameters(p, T)) for T in GRID])
    freq, loss = np.abs(modes), -2 * modes.real / np.abs(modes)  # loss factor = 2 zeta
    # hotter is softer: mode 1's natural frequency falls over the whole range (it never
    # rises by more than 1e-6 rad/s on the rubbery plateau) ...
    assert np.all(np.diff(freq) < 1e-6) and freq[0] - freq[-1] > 2.0
    assert np.all(np.diff(freq[(GRID > 17) & (GRID < 26)]) < -1e-3)  # the transition
    # ... to the rubbery plateau (the polymer's modulus spans a factor 1 + alpha)
    assert freq[-2] - freq[-1] < 1e-3
    # the modal loss factor peaks inside the range, where the polymer's own loss factor at
    # the mode's frequency is near its maximum: the transition region
    i = int(np.argmax(loss))
    assert 0 < i < GRID.size - 1 and loss[i] > 3 * max(loss[0], loss[-1])
    G = np.array([ghm_modulus(p, shift_factor(T) * f) for T, f in zip(GRID, freq, strict=True)])
    eta = G.imag / G.real
    assert eta[i] > 0.5 * eta.max()
    assert abs(GRID[i] - T_REF) < 5.0  # near where the thesis's parameters were set


def test_at_the_reference_temperature_the_plant_is_v1s_bit_for_bit():
    env = ACLDBeamEnv(temperature=T_REF)
    assert fixed_plant(env.nom, env.config) is env.nom.plant
    ref, got = ACLDBeamEnv(load_case="random"), ACLDBeamEnv(load_case="random", temperature=20.0)
    acts = np.random.default_rng(0).uniform(-150, 150, (200, 1)).astype(np.float32)
    for e in (ref, got):
        e.reset(seed=3)
    for a in acts:
        o1, r1, *_ = ref.step(a)
        o2, r2, *_ = got.step(a)
        assert o1.tobytes() == o2.tobytes() and r1 == r2


def test_temperature_is_model_mismatch_the_design_stays_nominal():
    warm = ACLDBeamEnv(temperature=30.0)
    v1 = ACLDBeamEnv()
    assert warm.nom is v1.nom and warm.batch.observer is v1.nom.kalman
    assert not np.allclose(warm.episode_plant.Ad, v1.nom.plant.Ad)
    ranged = ACLDBeamEnv(temperature_range=(17.0, 30.0))
    plants = []
    for seed in range(3):
        ranged.reset(seed=seed)
        plants.append(ranged.episode_plant.Ad)
    assert not np.allclose(plants[0], plants[1])
    ranged.reset(seed=0)
    np.testing.assert_array_equal(ranged.episode_plant.Ad, plants[0])  # seeded
    assert ranged.nom is v1.nom


@pytest.mark.parametrize(
    "kw",
    [
        {"temperature": 5.0},
        {"temperature": 45.0},
        {"temperature": 16.0},  # below the glass transition
        {"temperature_range": (30.0, 20.0)},
        {"temperature_range": (17.0,)},
        {"temperature_range": (17.0, 50.0)},
    ],
)
def test_temperatures_outside_the_model_are_refused(kw):
    with pytest.raises(ValueError, match="temperature"):
        ACLDBeamEnv(**kw)
