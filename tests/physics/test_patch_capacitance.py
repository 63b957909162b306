"""The patch's capacitance (acld_gym.physics.actuator): a parallel-plate capacitor through
the PZT's thickness, and the slew rate an amplifier's current limit gives on it."""

import pytest

from acld_gym.physics.actuator import (
    EPSILON_0,
    PZT_PERMITTIVITY,
    REFERENCE_CURRENT,
    REFERENCE_SLEW_RATE,
    patch_capacitance,
    slew_rate,
)
from acld_gym.physics.params import BeamParameters, table1


def test_default_patch_is_22_7_nF():
    # 1900 * 8.854e-12 F/m * (0.09 m * 0.015 m) / 0.001 m, by hand: 22.71 nF
    assert patch_capacitance() == pytest.approx(22.71e-9, rel=1e-3)
    assert patch_capacitance() == pytest.approx(
        EPSILON_0 * PZT_PERMITTIVITY * 0.09 * 0.015 / 0.001, rel=1e-12
    )
    assert EPSILON_0 == pytest.approx(8.8541878128e-12)
    assert PZT_PERMITTIVITY == 1900.0  # APC 850's K^T


def test_scales_with_area_over_thickness():
    base = patch_capacitance()
    # Table 1's 0.25 mm PZT: four times thinner, four times the capacitance
    assert patch_capacitance(table1()) == pytest.approx(4 * base, rel=1e-12)
    longer = BeamParameters(patch_length=0.18)
    assert patch_capacitance(longer) == pytest.approx(2 * base, rel=1e-12)
    assert patch_capacitance(relative_permittivity=950.0) == pytest.approx(base / 2, rel=1e-12)
    # half the thickness, twice the capacitance
    thin = patch_capacitance(BeamParameters(pzt_thickness=0.5e-3))
    assert thin == pytest.approx(2 * base, rel=1e-12)


def test_reference_slew_rate_is_the_current_limit_on_the_patch():
    c = patch_capacitance()
    assert REFERENCE_CURRENT == 0.095  # a +/-150 V bender driver's 95 mA
    assert REFERENCE_SLEW_RATE == pytest.approx(0.095 / c) == slew_rate(0.095, c)
    # thinner patch, more capacitance, slower voltage for the same current
    assert slew_rate(0.095, 2 * c) == pytest.approx(REFERENCE_SLEW_RATE / 2)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"relative_permittivity": 0.0}, "relative_permittivity"),
        ({"relative_permittivity": float("nan")}, "relative_permittivity"),
        ({"params": "steel"}, "params"),
        ({"params": BeamParameters(patch_length=0.0, patch_start=0.0)}, "bare beam"),
    ],
)
def test_bad_input_is_named(kwargs, word):
    with pytest.raises(ValueError, match=word):
        patch_capacitance(**kwargs)
