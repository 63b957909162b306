"""Tests of acld_gym.physics.loads: the thesis's tip loads (ch. 5).

Provenance: thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt ch. 5:
case 1 = 1 N pulse for 1 ms; case 2 = the same plus a second pulse at 0.1 s;
case 3 = 0.1 sin(179 t) N for 0.193 s (5.5 cycles).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from acld_gym.physics.loads import Harmonic, Pulse, TipLoad, thesis_load


def test_case1_values():
    f = thesis_load(1)
    assert f(0.0) == 1.0
    assert f(0.0005) == 1.0
    assert f(0.001) == 0.0  # left-closed interval: off at the end edge
    assert f(0.05) == 0.0
    assert_array_equal(f.breakpoints(), [0.0, 0.001])
    assert f.harmonic_frequencies == ()


def test_case2_second_pulse():
    f = thesis_load(2)
    assert_allclose(
        f(np.array([0.0, 0.0005, 0.001, 0.05, 0.1, 0.1005, 0.101, 0.2])), [1, 1, 0, 0, 1, 1, 0, 0]
    )
    assert_allclose(f.breakpoints(), [0.0, 0.001, 0.1, 0.101])


def test_case3_harmonic():
    f = thesis_load(3)
    t = np.linspace(0, 0.192, 500)
    assert_allclose(f(t), 0.1 * np.sin(179.0 * t), atol=1e-15)
    assert f(0.193) == 0.0
    assert np.all(f(np.linspace(0.1931, 1.0, 50)) == 0.0)
    assert_allclose(f.breakpoints(), [0.0, 0.193])
    assert f.harmonic_frequencies == (179.0,)
    # 0.193 s is about 5.5 cycles of 179 rad/s.
    assert 179.0 * 0.193 / (2 * np.pi) == pytest.approx(5.5, abs=0.01)


def _eval_piece(piece, t):
    return piece.const + sum(a * np.sin(w * t + ph) for a, w, ph in piece.harmonics)


@pytest.mark.parametrize("case", [1, 2, 3])
def test_piece_reproduces_load(case):
    f = thesis_load(case)
    edges = np.concatenate([f.breakpoints(), [1.0]])
    for t0, t1 in zip(edges[:-1], edges[1:], strict=True):
        p = f.piece(t0, t1)
        ts = np.linspace(t0, t1, 7)[:-1] + 1e-12
        for t in ts:
            assert _eval_piece(p, t) == pytest.approx(float(f(t)), abs=1e-12)


def test_piece_with_phase_and_offset_start():
    f = TipLoad((Harmonic(2.0, 50.0, 0.3, 0.2, phase=0.7), Pulse(0.35, 0.1, -1.5)))
    p = f.piece(0.35, 0.45)
    assert p.const == -1.5
    assert len(p.harmonics) == 1
    for t in (0.36, 0.4, 0.44):
        assert _eval_piece(p, t) == pytest.approx(float(f(t)), abs=1e-12)
        assert float(f(t)) == pytest.approx(2.0 * np.sin(50.0 * (t - 0.3) + 0.7) - 1.5)


@pytest.mark.parametrize("case", [0, 4, "1"])
def test_bad_case(case):
    with pytest.raises(ValueError, match="case"):
        thesis_load(case)


@pytest.mark.parametrize("dur", [0.0, -1e-3])
def test_pulse_bad_duration(dur):
    with pytest.raises(ValueError, match="duration"):
        Pulse(0.0, dur, 1.0)


def test_pulse_nonfinite():
    with pytest.raises(ValueError):
        Pulse(np.inf, 1e-3, 1.0)
    with pytest.raises(ValueError):
        Pulse(0.0, 1e-3, np.nan)


def test_harmonic_bad_args():
    with pytest.raises(ValueError, match="duration"):
        Harmonic(1.0, 10.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="frequency"):
        Harmonic(1.0, 0.0, 0.0, 1.0)


# --- the named load cases (issue 21: one registry) ------------------------------------------
def test_registry_names_every_case_once():
    from acld_gym.physics.loads import (
        LOAD_CASES,
        RANDOM,
        case_label,
        case_load,
        check_load_case,
        parse_load_case,
    )

    assert LOAD_CASES == (1, 2, 3, RANDOM)
    for case in (1, 2, 3):
        assert case_load(case) == thesis_load(case)
        assert parse_load_case(str(case)) == case == check_load_case(np.int64(case))
    assert case_load(RANDOM) is None and case_label(RANDOM) == "random"
    custom = TipLoad((Pulse(0.0, 1e-3, 2.0),))
    assert case_load(custom) is custom and case_label(custom) == "custom"
    for bad in (0, 4, 1.0, True, "1", "rand", None):
        with pytest.raises(ValueError, match="load_case"):
            check_load_case(bad)
    for bad in ("4", 1.0, True, custom):
        with pytest.raises(ValueError, match="load case"):
            parse_load_case(bad)


def _main_random_load(rng, duration, grid, modes):
    """The random mix as acld-gym 0.2 drew it (one ``uniform`` call per number): the
    oracle that the mix stays what it is."""
    from acld_gym.physics.loads import Samples

    comps = []
    for _ in range(int(rng.integers(1, 4))):
        start = np.round(rng.uniform(0.0, 0.7 * duration) / grid) * grid
        width = max(np.round(rng.uniform(5e-4, 3e-3) / grid), 1) * grid
        comps.append(Pulse(float(start), float(width), float(rng.uniform(-1.5, 1.5))))
    if rng.uniform() < 0.5:
        w0 = modes[0] if rng.uniform() < 0.7 else modes[1]
        comps.append(
            Harmonic(
                float(rng.uniform(0.0, 0.08)),
                float(w0 * rng.uniform(0.95, 1.05)),
                float(rng.uniform(0.0, 0.5 * duration)),
                float(rng.uniform(0.05, 0.3)),
                float(rng.uniform(0, 2 * np.pi)),
            )
        )
    if rng.uniform() < 0.5:
        step = max(np.round(2e-3 / grid), 1) * grid
        n = int(duration / step) + 1
        white = rng.normal(0.0, 1.0, n)
        smooth = np.convolve(white, np.ones(4) / 2.0, mode="same")
        comps.append(Samples(0.0, float(step), tuple(0.05 * smooth)))
    return TipLoad(tuple(comps))


@pytest.mark.parametrize("duration, grid", [(1.0, 1e-4), (0.05, 1e-4), (0.3, 5e-5)])
def test_random_mix_has_the_same_draws_and_numbers(duration, grid):
    from acld_gym.physics.loads import random_load

    for seed in range(300):
        a, b = np.random.default_rng(seed), np.random.default_rng(seed)
        assert random_load(a, duration, grid, (177.4, 976.2)) == _main_random_load(
            b, duration, grid, (177.4, 976.2)
        )
        assert a.bit_generator.state == b.bit_generator.state  # the draws that follow too


# --- components ---------------------------------------------------------------------------
def test_samples_are_validated_compared_and_scaled():
    from acld_gym.physics.loads import Samples

    s = Samples(0.1, 0.5, (1.0, 3.0, 2.0))
    assert s.end == 1.1 and s == Samples(0.1, 0.5, np.array([1.0, 3.0, 2.0]))
    assert hash(s) == hash(Samples(0.1, 0.5, [1.0, 3.0, 2.0])) and s != Samples(0.1, 0.5, (1, 3))
    assert not s.values.flags.writeable
    f = TipLoad((s,))
    assert_allclose(f(np.array([0.0, 0.1, 0.35, 0.6, 1.1])), [0.0, 1.0, 2.0, 3.0, 0.0])
    half = TipLoad((s, Pulse(0.0, 0.2, 4.0), Harmonic(1.0, 3.0, 0.0, 1.0))).scaled(0.5)
    t = np.linspace(0, 1.2, 50)
    assert_allclose(
        half(t), 0.5 * TipLoad((s, Pulse(0.0, 0.2, 4.0), Harmonic(1.0, 3.0, 0.0, 1.0)))(t)
    )
    for bad in ((1.0,), (1.0, np.nan), ("a", "b"), (True, 1.0), ((1.0, 2.0), (3.0, 4.0))):
        with pytest.raises(ValueError, match="Samples.values"):
            Samples(0.0, 1.0, bad)
    with pytest.raises(ValueError, match="components"):
        TipLoad([Pulse(0.0, 1.0, 1.0)])


# --- the excitation library ---------------------------------------------------------------
def test_band_limited_noise_has_its_std_and_band():
    from acld_gym.physics.loads import band_limited_noise

    load = band_limited_noise(np.random.default_rng(0), 4.0, 0.2, 100.0, step=1e-4)
    x = load.components[0].values
    assert np.std(x) == pytest.approx(0.2, rel=1e-12)
    spectrum = np.abs(np.fft.rfft(x)) ** 2
    f = np.fft.rfftfreq(x.size, 1e-4)
    # white noise would put 47x more power above 300 Hz than below 100 Hz; the filter (8th
    # order forward and backward) leaves the edges' transients only
    assert spectrum[f > 300].sum() < 1e-3 * spectrum[f < 100].sum()
    assert load == band_limited_noise(np.random.default_rng(0), 4.0, 0.2, 100.0, step=1e-4)
    with pytest.raises(ValueError, match="Nyquist"):
        band_limited_noise(np.random.default_rng(0), 1.0, 0.2, 6000.0, step=1e-4)


@pytest.mark.parametrize("spacing", ["linear", "log"])
def test_sine_sweep_runs_through_its_frequencies(spacing):
    from acld_gym.physics.loads import sine_sweep

    load = sine_sweep(0.5, 20.0, 200.0, 1.0, start=0.2, step=1e-5, spacing=spacing)
    s = load.components[0]
    assert s.start == 0.2 and s.end == pytest.approx(1.2) and np.abs(s.values).max() <= 0.5
    x = np.asarray(s.values)
    up = np.flatnonzero((x[:-1] <= 0) & (x[1:] > 0)) * 1e-5  # upward zero crossings [s]
    freq = 1.0 / np.diff(up)  # instantaneous frequency [Hz] at the crossings' midpoints
    tau = 0.5 * (up[1:] + up[:-1])
    want = 20.0 + 180.0 * tau if spacing == "linear" else 20.0 * 10.0**tau
    assert_allclose(freq, want, rtol=0.02)
    with pytest.raises(ValueError, match="step"):
        sine_sweep(0.5, 20.0, 200.0, 1.0, step=1e-3)


def test_half_sine_shock_is_a_half_sine():
    from acld_gym.physics.loads import half_sine_shock

    load = half_sine_shock(3.0, 2e-3, start=0.01)
    t = np.linspace(0.01, 0.012, 20001)[:-1]
    assert load(0.011) == pytest.approx(3.0) and load(0.0099) == 0.0 and load(0.012) == 0.0
    # its impulse: 2 A T / pi
    assert np.trapezoid(load(t), t) == pytest.approx(2 * 3.0 * 2e-3 / np.pi, rel=1e-6)
    # one harmonic, so the continuous simulator integrates it exactly
    assert load.piece(0.0105, 0.0115).harmonics


def test_recorded_load_is_linear_between_its_samples():
    from acld_gym.physics.loads import recorded_load

    values = np.array([0.0, 1.0, -2.0, 0.5])
    load = recorded_load(values, 1e-3, start=0.1)
    assert_allclose(load(0.1 + 1e-3 * np.arange(3)), values[:3])
    assert load(0.1005) == pytest.approx(0.5) and load(0.0999) == 0.0 and load(0.1031) == 0.0
    for bad in (np.ones((2, 2)), np.array(["a", "b"])):
        with pytest.raises(ValueError, match="values"):
            recorded_load(bad, 1e-3)


# --- issue 65: a TipLoad is evaluated from its components alone -----------------------------
class _Silent(TipLoad):
    def __call__(self, t):
        return np.zeros_like(np.asarray(t, dtype=float))


class _OwnPieces(TipLoad):
    def piece(self, t0, t1):
        raise AssertionError("never called")


class _OwnComponents(TipLoad):
    @property
    def components(self):
        return ()


class _Labelled(TipLoad):
    """A subclass that only adds a method: the same load."""

    def label(self) -> str:
        return "labelled"


class _Unchecked(TipLoad):
    def __post_init__(self):  # skips TipLoad's validation
        pass


@pytest.mark.parametrize("cls, method", [(_Silent, "__call__"), (_OwnPieces, "piece")])
def test_a_subclass_that_overrides_evaluation_is_refused_naming_it(cls, method):
    from acld_gym.physics.loads import case_load, check_load_case

    load = cls((Pulse(0.0, 1e-3, 1.0),))
    for name in ("load_case", "options['load']"):
        with pytest.raises(ValueError, match=rf"^{re.escape(name)}: .*override {method}\b"):
            check_load_case(load, name)
    with pytest.raises(ValueError, match="TipLoad subclass"):
        case_load(load)


def test_a_subclass_with_its_own_components_property_is_refused():
    from acld_gym.physics.loads import check_load_case

    load = object.__new__(_OwnComponents)  # its property shadows the field: no __init__
    with pytest.raises(ValueError, match="override components"):
        check_load_case(load)


def test_a_subclass_that_adds_methods_only_is_the_same_load():
    from acld_gym.physics.loads import check_load_case

    comps = (Pulse(0.0, 1e-3, 1.0), Harmonic(0.1, 179.0, 0.0, 0.193))
    load = _Labelled(comps)
    assert check_load_case(load) is load
    t = np.linspace(0.0, 0.3, 301)
    assert_array_equal(load(t), TipLoad(comps)(t))


def test_a_subclass_that_skips_validation_is_validated_at_use():
    from acld_gym.physics.loads import check_load_case

    bad = _Unchecked(("not a component",))
    with pytest.raises(ValueError, match="TipLoad.components"):
        check_load_case(bad)


def test_components_must_be_of_the_component_types_themselves():
    class Loud(Pulse):
        pass

    with pytest.raises(ValueError, match="TipLoad.components"):
        TipLoad((Loud(0.0, 1e-3, 1.0),))


def test_scaled_keeps_every_number_of_each_component():
    load = TipLoad((Pulse(0.01, 2e-3, 0.7), Harmonic(0.3, 400.0, 0.02, 0.1, 0.4)))
    half = load.scaled(-0.5)
    assert half.components == (
        Pulse(0.01, 2e-3, -0.35),
        Harmonic(-0.15, 400.0, 0.02, 0.1, 0.4),
    )
    with pytest.raises(ValueError, match=r"Harmonic\.phase"):
        Harmonic(1.0, 2.0, 0.0, 1.0, float("nan"))
