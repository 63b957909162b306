"""Physical parameters and finite-element mesh of the ACLD cantilever.

Both are frozen dataclasses validated on construction. Every field carries its
unit, thesis symbol and description in ``field.metadata`` so that documentation
tables are generated from the code (see :func:`parameter_table`). Derived
quantities (areas, second moments, layer offsets, element lengths) are
properties, never stored copies, so a :func:`dataclasses.replace` can never
leave them stale.

Defaults are the values the thesis's MATLAB code actually used
(``SystemMatrices03.m``), which are the ones that reproduce its results; the
:func:`table1` preset has the values as printed in the thesis's Table 1.
"""

from __future__ import annotations

import dataclasses
import numbers
from dataclasses import dataclass, field
from typing import Any

__all__ = ["BeamParameters", "Mesh", "table1", "parameter_table", "split_overrides"]


def _p(
    default: float,
    unit: str,
    symbol: str,
    doc: str,
    *,
    allow_zero: bool = False,
    allow_negative: bool = False,
) -> Any:
    """A dataclass field with documentation metadata and a validation rule."""
    return field(
        default=default,
        metadata={
            "unit": unit,
            "symbol": symbol,
            "doc": doc,
            "allow_zero": allow_zero,
            "allow_negative": allow_negative,
        },
    )


#: Physically plausible magnitudes per unit (nonzero values): generous, but they keep the
#: finite-element matrices and their solves finite (a density of 1e-300 kg/m^3 or a shear
#: factor of 1e308 is an input error, not a beam).
MAGNITUDES: dict[str, tuple[float, float]] = {
    "m": (1e-7, 100.0),
    "N/m^2": (1e-3, 1e13),
    "kg/m^3": (1e-6, 1e5),
    "m/V": (1e-18, 1e-6),
    "rad/s": (1e-3, 1e9),
    "1/s": (1e-9, 1e6),
    "s": (1e-15, 1.0),
    "-": (1e-6, 1e6),
}


def _validate(obj: Any, allow_zero: tuple[str, ...] = ()) -> None:
    """Check every numeric field against its sign rule and the plausible magnitudes of
    its unit (:data:`MAGNITUDES`); raise ``ValueError`` naming it.

    ``allow_zero`` names fields that may also be zero in this particular case.
    """
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"{type(obj).__name__}.{f.name} must be a real number, got {value!r}")
        if value != value or value in (float("inf"), float("-inf")):
            raise ValueError(f"{type(obj).__name__}.{f.name} must be finite, got {value!r}")
        if not f.metadata.get("allow_negative") and (
            value < 0
            or (value == 0 and not f.metadata.get("allow_zero") and f.name not in allow_zero)
        ):
            need = "non-negative" if f.metadata.get("allow_zero") else "positive"
            raise ValueError(
                f"{type(obj).__name__}.{f.name} must be {need} "
                f"[{f.metadata['unit']}], got {value!r}"
            )
        unit = f.metadata.get("unit")
        if (
            value != 0
            and unit in MAGNITUDES
            and isinstance(value, float | int)
            and not isinstance(obj, Mesh)
        ):
            lo, hi = MAGNITUDES[unit]
            if not lo <= abs(value) <= hi:
                raise ValueError(
                    f"{type(obj).__name__}.{f.name} must have a magnitude in "
                    f"[{lo:g}, {hi:g}] {unit} (a physical value), got {value!r}"
                )


@dataclass(frozen=True)
class BeamParameters:
    """Materials and geometry of the partially ACLD-treated cantilever.

    Layers: ``b`` = aluminium base beam, ``s`` = viscoelastic material (VEM,
    GHM model), ``c`` = piezoelectric constraining layer (PZT, the actuator).
    The VEM is modelled in shear only (its extensional modulus is zero in the
    thesis's MATLAB, ``Es = 0*14e6``).

    ``patch_length = 0`` (with ``patch_start = 0``) describes the bare beam without any
    ACLD element; its mesh is ``Mesh(0, 0, n)`` (all elements in ``n_after``).
    """

    length: float = _p(0.3, "m", "L", "Length of the beam")
    width: float = _p(0.015, "m", "b", "Width of beam, VEM and PZT")
    beam_thickness: float = _p(0.003, "m", "t_b", "Beam thickness")
    beam_youngs_modulus: float = _p(7.0e10, "N/m^2", "E_b", "Beam elastic modulus")
    beam_shear_modulus: float = _p(2.6e10, "N/m^2", "G_b", "Beam shear modulus")
    beam_density: float = _p(2700.0, "kg/m^3", "rho_b", "Beam density")
    pzt_thickness: float = _p(
        0.001, "m", "t_c", "PZT thickness (MATLAB value; Table 1 prints 0.25 mm)"
    )
    pzt_youngs_modulus: float = _p(6.49e10, "N/m^2", "E_c", "PZT elastic modulus")
    pzt_shear_modulus: float = _p(
        2.496e10, "N/m^2", "G_c", "PZT shear modulus (MATLAB value; Table 1 prints 2.49e10)"
    )
    pzt_density: float = _p(7600.0, "kg/m^3", "rho_c", "PZT density")
    d31: float = _p(-175e-12, "m/V", "d_31", "PZT piezoelectric constant", allow_negative=True)
    vem_thickness: float = _p(
        0.00025, "m", "t_s", "VEM thickness (MATLAB value; Table 1 prints 1 mm)"
    )
    vem_density: float = _p(1250.0, "kg/m^3", "rho_s", "VEM density")
    vem_youngs_modulus: float = _p(
        0.0, "N/m^2", "E_s", "VEM extensional modulus (0 in the MATLAB)", allow_zero=True
    )
    ghm_kappa: float = _p(1.0e6, "N/m^2", "kappa", "VEM (GHM) equilibrium shear modulus")
    ghm_alpha: float = _p(1.0, "-", "alpha_r", "GHM mini-oscillator strength")
    ghm_omega: float = _p(1000.0, "rad/s", "omega_r", "GHM mini-oscillator frequency")
    ghm_zeta: float = _p(4.0, "-", "zeta", "GHM mini-oscillator damping ratio")
    shear_correction: float = _p(5.0 / 6.0, "-", "k_alpha", "Shear correction factor")
    rayleigh_mass: float = _p(
        0.64, "1/s", "a_hat", "Rayleigh damping, mass coefficient", allow_zero=True
    )
    rayleigh_stiffness: float = _p(
        1.2e-6, "s", "b_hat", "Rayleigh damping, stiffness coefficient", allow_zero=True
    )
    patch_start: float = _p(
        0.03, "m", "-", "Distance of the ACLD patch from the clamp", allow_zero=True
    )
    patch_length: float = _p(
        0.09,
        "m",
        "-",
        "ACLD patch length (MATLAB: 30% of L; the text says 100 mm)",
        allow_zero=True,
    )  # 0: bare beam (see the class docstring)

    def __post_init__(self) -> None:
        _validate(self)
        if self.patch_length == 0 and self.patch_start != 0:
            raise ValueError(
                f"BeamParameters.patch_start must be 0 when patch_length = 0 "
                f"(a bare beam, no ACLD patch), got {self.patch_start!r}"
            )
        if self.patch_start + self.patch_length > self.length * (1 + 1e-12):
            raise ValueError(
                f"BeamParameters.patch_length: patch_start + patch_length = "
                f"{self.patch_start + self.patch_length:g} m exceeds length = {self.length:g} m "
                "(the patch must fit on the beam)"
            )

    # --- derived cross-section properties (never stored) -------------------
    @property
    def beam_area(self) -> float:
        """A_b = b t_b [m^2]."""
        return self.width * self.beam_thickness

    @property
    def beam_inertia(self) -> float:
        """I_b = b t_b^3 / 12 [m^4]."""
        return self.width * self.beam_thickness**3 / 12.0

    @property
    def pzt_area(self) -> float:
        """A_c = b t_c [m^2]."""
        return self.width * self.pzt_thickness

    @property
    def pzt_inertia(self) -> float:
        """I_c = b t_c^3 / 12 [m^4]."""
        return self.width * self.pzt_thickness**3 / 12.0

    @property
    def vem_area(self) -> float:
        """A_s = b t_s [m^2]."""
        return self.width * self.vem_thickness

    @property
    def vem_inertia(self) -> float:
        """I_s = b t_s^3 / 12 [m^4]."""
        return self.width * self.vem_thickness**3 / 12.0

    @property
    def pzt_offset(self) -> float:
        """h = t_s + (t_b + t_c)/2: beam mid-plane to PZT mid-plane [m]."""
        return self.vem_thickness + 0.5 * (self.beam_thickness + self.pzt_thickness)

    @property
    def piezo_force_per_volt(self) -> float:
        """E_c d_31 b: axial force in the PZT per applied volt [N/V]."""
        return self.pzt_youngs_modulus * self.d31 * self.width


@dataclass(frozen=True)
class Mesh:
    """Element counts of the three beam sections (thesis: 1 + 1 + 3).

    ``n_patch = 0`` is allowed only with ``n_before = 0``: the bare beam
    (``BeamParameters.patch_length = 0``), whose elements are all in ``n_after``.
    """

    n_before: int = field(
        default=1,
        metadata={
            "unit": "-",
            "symbol": "nelL",
            "doc": "Timoshenko elements between clamp and patch",
            "allow_zero": True,
        },
    )
    n_patch: int = field(
        default=1, metadata={"unit": "-", "symbol": "nelC", "doc": "ACLD elements on the patch"}
    )
    n_after: int = field(
        default=3,
        metadata={
            "unit": "-",
            "symbol": "nelR",
            "doc": "Timoshenko elements between patch and tip",
            "allow_zero": True,
        },
    )

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, numbers.Integral):
                raise ValueError(f"Mesh.{f.name} must be an integer, got {value!r}")
            object.__setattr__(self, f.name, int(value))
        # A bare beam (no ACLD patch, patch_length = 0) has n_patch = 0; all its elements
        # are then counted in n_after, so n_before = 0 as well. Otherwise n_patch >= 1.
        if self.n_patch == 0 and self.n_before != 0:
            raise ValueError(
                f"Mesh.n_patch must be positive [-], got 0 (n_patch = 0 is only "
                f"for a bare beam, patch_length = 0, whose elements are all in "
                f"n_after: set n_before = 0, not {self.n_before!r})"
            )
        _validate(self, allow_zero=("n_patch",))

    def refined(self, factor: int) -> Mesh:
        """The same mesh with every section split into ``factor`` times as many elements."""
        if not isinstance(factor, int) or factor < 1:
            raise ValueError(f"factor must be a positive integer, got {factor!r}")
        return Mesh(self.n_before * factor, self.n_patch * factor, self.n_after * factor)


def table1() -> BeamParameters:
    """The parameters exactly as printed in the thesis's Table 1.

    Differs from the default (the MATLAB values) in the layer thicknesses
    (PZT 0.25 mm, VEM 1 mm, i.e. swapped) and ``G_c`` = 2.49e10 N/m^2. This
    preset does *not* reproduce the thesis's results (first resonance and
    load case 3 frequency); it is shipped for comparison.
    """
    return BeamParameters(pzt_thickness=0.00025, vem_thickness=0.001, pzt_shear_modulus=2.49e10)


PRESETS = {"matlab": BeamParameters, "table1": table1}


def split_overrides(overrides: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Route keyword overrides to :class:`BeamParameters` or :class:`Mesh` fields.

    Raises ``TypeError`` naming any keyword that belongs to neither.
    """
    pnames = {f.name for f in dataclasses.fields(BeamParameters)}
    mnames = {f.name for f in dataclasses.fields(Mesh)}
    unknown = sorted(set(overrides) - pnames - mnames)
    if unknown:
        raise TypeError(
            f"unknown parameter(s) {unknown}; expected fields of BeamParameters or Mesh"
        )
    return (
        {k: v for k, v in overrides.items() if k in pnames},
        {k: v for k, v in overrides.items() if k in mnames},
    )


def parameter_table(params: BeamParameters | None = None, mesh: Mesh | None = None) -> str:
    """A Markdown table of all parameters with symbol, value, unit and description."""
    params = BeamParameters() if params is None else params
    mesh = Mesh() if mesh is None else mesh
    rows = ["| field | symbol | value | unit | description |", "|---|---|---|---|---|"]
    for obj in (params, mesh):
        for f in dataclasses.fields(obj):
            md = f.metadata
            rows.append(
                f"| `{f.name}` | {md['symbol']} | {getattr(obj, f.name):g} | "
                f"{md['unit']} | {md['doc']} |"
            )
    return "\n".join(rows)
