"""Tests of acld_gym.physics.params: defaults, presets, derived quantities, validation.

Provenance of reference values:
* "thesis MATLAB" = SystemMatrices03.m in Appendix A of the thesis
  (/work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt, ~line 1060).
* "thesis Table 1" = the parameter table as printed in ch. 5, sec. 5.2.
"""

from __future__ import annotations

import dataclasses

import pytest
from numpy.testing import assert_allclose

from acld_gym.physics.model import build_model
from acld_gym.physics.params import BeamParameters, Mesh, parameter_table, split_overrides, table1

# --- defaults -----------------------------------------------------------------


def test_defaults_equal_matlab_values():
    # thesis MATLAB (SystemMatrices03.m): tb=.003, ts=.00025, tc=.001, Gc=2.496e10, L=.3,
    # b=.015, PLL=0.1 (patch start 0.03 m), PLC=0.3 (patch length 0.09 m), ...
    p = BeamParameters()
    expected = {
        "length": 0.3,
        "width": 0.015,
        "beam_thickness": 0.003,
        "beam_youngs_modulus": 7.0e10,
        "beam_shear_modulus": 2.6e10,
        "beam_density": 2700.0,
        "pzt_thickness": 1.0e-3,
        "pzt_youngs_modulus": 6.49e10,
        "pzt_shear_modulus": 2.496e10,
        "pzt_density": 7600.0,
        "d31": -175e-12,
        "vem_thickness": 0.25e-3,
        "vem_density": 1250.0,
        "vem_youngs_modulus": 0.0,
        "ghm_kappa": 1.0e6,
        "ghm_alpha": 1.0,
        "ghm_omega": 1000.0,
        "ghm_zeta": 4.0,
        "shear_correction": 5.0 / 6.0,
        "rayleigh_mass": 0.64,
        "rayleigh_stiffness": 1.2e-6,
        "patch_start": 0.03,
        "patch_length": 0.09,
    }
    for name, value in expected.items():
        assert getattr(p, name) == pytest.approx(value, rel=1e-15, abs=0.0), name
    # every field is covered by the list above (no unchecked default)
    assert {f.name for f in dataclasses.fields(BeamParameters)} == set(expected)


def test_default_mesh_is_thesis_1_1_3():
    # thesis MATLAB: nelL = 1, nelC = 1, nelR = 3
    assert (Mesh().n_before, Mesh().n_patch, Mesh().n_after) == (1, 1, 3)


def test_table1_preset_values():
    # thesis Table 1 prints PZT 0.25 mm, VEM 1 mm, Gc = 2.49e10 (swapped w.r.t. the MATLAB)
    t = table1()
    assert t.pzt_thickness == pytest.approx(0.25e-3, rel=1e-15)
    assert t.vem_thickness == pytest.approx(1.0e-3, rel=1e-15)
    assert t.pzt_shear_modulus == pytest.approx(2.49e10, rel=1e-15)
    assert t != BeamParameters()
    # everything else equals the MATLAB defaults
    d = BeamParameters()
    for f in dataclasses.fields(BeamParameters):
        if f.name not in ("pzt_thickness", "vem_thickness", "pzt_shear_modulus"):
            assert getattr(t, f.name) == getattr(d, f.name), f.name


# --- derived quantities -------------------------------------------------------


def _check_derived(p: BeamParameters) -> None:
    b, tb, ts, tc = p.width, p.beam_thickness, p.vem_thickness, p.pzt_thickness
    # rectangular sections: A = b t, I = b t^3 / 12; h = ts + (tb + tc)/2 (thesis MATLAB)
    assert_allclose(p.beam_area, b * tb, rtol=1e-14)
    assert_allclose(p.vem_area, b * ts, rtol=1e-14)
    assert_allclose(p.pzt_area, b * tc, rtol=1e-14)
    assert_allclose(p.beam_inertia, b * tb**3 / 12, rtol=1e-14)
    assert_allclose(p.vem_inertia, b * ts**3 / 12, rtol=1e-14)
    assert_allclose(p.pzt_inertia, b * tc**3 / 12, rtol=1e-14)
    assert_allclose(p.pzt_offset, ts + (tb + tc) / 2, rtol=1e-14)
    assert_allclose(p.piezo_force_per_volt, p.pzt_youngs_modulus * p.d31 * b, rtol=1e-14)


def test_derived_properties_default_numbers():
    p = BeamParameters()
    _check_derived(p)
    # hand-computed numbers for the MATLAB defaults
    assert_allclose(p.beam_area, 4.5e-5, rtol=1e-12)
    assert_allclose(p.beam_inertia, 3.375e-11, rtol=1e-12)
    assert_allclose(p.pzt_area, 1.5e-5, rtol=1e-12)
    assert_allclose(p.vem_area, 3.75e-6, rtol=1e-12)
    assert_allclose(p.pzt_offset, 0.00225, rtol=1e-12)  # 0.25 mm + (3 + 1)/2 mm


def test_derived_properties_follow_replace():
    p = BeamParameters()
    q = dataclasses.replace(
        p, width=0.02, beam_thickness=0.004, vem_thickness=0.5e-3, pzt_thickness=0.3e-3
    )
    _check_derived(q)
    assert q.beam_area != p.beam_area
    assert q.pzt_offset == pytest.approx(0.5e-3 + (0.004 + 0.3e-3) / 2)
    _check_derived(table1())


def test_frozen():
    p = BeamParameters()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.length = 1.0  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        Mesh().n_patch = 3  # type: ignore[misc]


# --- validation ---------------------------------------------------------------

BAD_PARAMS = [
    ("length", 0.0),
    ("length", -0.3),
    ("width", 0.0),
    ("beam_thickness", 0.0),
    ("beam_thickness", -1e-3),
    ("pzt_thickness", 0.0),
    ("vem_thickness", -0.25e-3),
    ("beam_youngs_modulus", 0.0),
    ("beam_youngs_modulus", -7e10),
    ("pzt_youngs_modulus", -1.0),
    ("beam_shear_modulus", 0.0),
    ("pzt_shear_modulus", -1.0),
    ("vem_youngs_modulus", -1.0),
    ("beam_density", 0.0),
    ("pzt_density", -7600.0),
    ("vem_density", 0.0),
    ("ghm_kappa", 0.0),
    ("ghm_omega", -1.0),
    ("shear_correction", 0.0),
    ("rayleigh_mass", -0.1),
    ("length", float("nan")),
    ("beam_youngs_modulus", float("nan")),
    ("pzt_density", float("inf")),
    ("length", "0.3"),
]


@pytest.mark.parametrize("name,value", BAD_PARAMS)
def test_invalid_parameter_raises_naming_field(name, value):
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        BeamParameters(**{name: value})


@pytest.mark.parametrize(
    "name,value",
    [
        ("vem_youngs_modulus", 0.0),
        ("rayleigh_mass", 0.0),
        ("rayleigh_stiffness", 0.0),
        ("patch_start", 0.0),
        ("d31", 175e-12),
        ("d31", -175e-12),
    ],
)
def test_allowed_boundary_values(name, value):
    # zero Es is the MATLAB value; zero damping and a patch at the clamp are legitimate
    assert getattr(BeamParameters(**{name: value}), name) == value


def test_patch_must_fit():
    with pytest.raises(ValueError, match="patch_length"):
        BeamParameters(patch_start=0.25, patch_length=0.09)  # 0.34 > 0.3
    with pytest.raises(ValueError, match="patch"):
        BeamParameters(length=0.1)  # default patch 0.03 + 0.09 > 0.1
    # exactly fitting is fine
    p = BeamParameters(patch_start=0.21, patch_length=0.09)
    assert p.patch_start + p.patch_length == pytest.approx(p.length)


@pytest.mark.parametrize(
    "name,value", [("n_patch", 0), ("n_patch", -1), ("n_before", -1), ("n_after", -2)]
)
def test_mesh_bad_counts(name, value):
    with pytest.raises(ValueError, match=name):
        Mesh(**{name: value})


@pytest.mark.parametrize(
    "name,value",
    [
        ("n_patch", 1.5),
        ("n_after", 3.0),
        ("n_before", "1"),
        ("n_patch", True),
        ("n_after", float("nan")),
    ],
)
def test_mesh_non_integer_counts(name, value):
    with pytest.raises(ValueError, match=name):
        Mesh(**{name: value})


def test_mesh_zero_outer_sections_allowed_and_refined():
    assert Mesh(0, 2, 0).n_before == 0
    assert Mesh(1, 1, 3).refined(4) == Mesh(4, 4, 12)
    with pytest.raises(ValueError):
        Mesh().refined(0)


def test_build_model_invalid_override_raises_value_error():
    with pytest.raises(ValueError, match="beam_thickness"):
        build_model(beam_thickness=-0.003)
    with pytest.raises(ValueError, match="n_patch"):
        build_model(n_patch=0)


def test_build_model_unknown_keyword_is_type_error():
    with pytest.raises(TypeError, match="unknown_kw"):
        build_model(unknown_kw=1)


def test_split_overrides_routes_fields():
    pkw, mkw = split_overrides({"length": 0.4, "n_after": 6, "ghm_zeta": 2.0})
    assert pkw == {"length": 0.4, "ghm_zeta": 2.0}
    assert mkw == {"n_after": 6}
    with pytest.raises(TypeError, match="bogus"):
        split_overrides({"bogus": 1, "length": 0.4})


def test_parameter_table_contains_every_field():
    table = parameter_table()
    for cls in (BeamParameters, Mesh):
        for f in dataclasses.fields(cls):
            assert f"`{f.name}`" in table, f.name
            assert f.metadata["unit"] in table
    # one header + one separator + one row per field
    n_fields = len(dataclasses.fields(BeamParameters)) + len(dataclasses.fields(Mesh))
    assert len(table.splitlines()) == 2 + n_fields
    # values are those of the given parameters
    assert "| 0.00025 |" in parameter_table(table1())  # PZT thickness of Table 1
