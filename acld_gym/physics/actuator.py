r"""The piezoelectric patch as the actuator: its voltage limit, its capacitance, and the
amplifier that drives it.

``V_LIMIT`` is the largest voltage the patch takes in the thesis's saturated runs (sec. 5.3,
"Saturation limits of 120V to -120V were enforced to replicate realistic voltage
constraints"): the env's action bound, the baselines' and the bound's limit.

**Capacitance.** The patch is a plate capacitor through its thickness,
:math:`C = \varepsilon_0 K^T_3 A / t_c` with A = length x width the electroded area. The
thesis's PZT (E_c = 64.9 GPa, d31 = -175 pm/V, 7600 kg/m^3) is a PZT-5A (Navy type II):
APC 850 has exactly d31 = -175 pm/V and 7600 kg/m^3, and a relative permittivity
:data:`PZT_PERMITTIVITY` K^T_3 = 1900 (APC International, "Physical and Piezoelectric
Properties of APC Materials", https://www.americanpiezo.com/apc-materials/
physical-piezoelectric-properties.html; CTS 3195STD, also PZT-5A: 1800, the same
d31). With the thesis MATLAB's patch (90 x 15 mm, 1 mm) that is 22.7 nF
(:func:`patch_capacitance`).

**Amplifier.** A linear amplifier's output current is limited, so on a capacitive load its
voltage can change at most at :math:`\dot V = I_{max} / C` (:func:`slew_rate`; e.g.
Thorlabs' "Piezo Driver Bandwidth Tutorial": slew rate = current limit / load capacitance).
The reference is a bender driver for +/-150 V, PiezoDrive's BD150, peak current 95 mA
(Micromechatronics / PiezoDrive BD series data, https://mmech.com/piezodrive-amplifiers/
bd-series): :data:`REFERENCE_SLEW_RATE` = 95 mA / 22.7 nF = 4.2e6 V/s, a 240 V swing in
57 us, far below the 1 ms control period -- the slew limit only matters for weaker
drivers or larger patches. Its small-signal bandwidth makes a first-order lag from the
command to the patch voltage (:func:`with_amplifier`).
"""

from __future__ import annotations

import numpy as np

from acld_gym.physics.params import BeamParameters
from acld_gym.util.validate import check_real

__all__ = [
    "V_LIMIT",
    "EPSILON_0",
    "PZT_PERMITTIVITY",
    "REFERENCE_CURRENT",
    "REFERENCE_SLEW_RATE",
    "patch_capacitance",
    "slew_rate",
    "with_amplifier",
]

#: Voltage limit of the PZT patch [V] (thesis sec. 5.3).
V_LIMIT = 120.0
#: Vacuum permittivity [F/m] (CODATA 2018).
EPSILON_0 = 8.8541878128e-12
#: Relative permittivity K^T_3 of the patch's PZT-5A at constant stress [-] (APC 850).
PZT_PERMITTIVITY = 1900.0
#: Peak output current of the reference amplifier [A] (PiezoDrive BD150).
REFERENCE_CURRENT = 0.095


def patch_capacitance(
    params: BeamParameters | None = None, relative_permittivity: float = PZT_PERMITTIVITY
) -> float:
    r"""Capacitance of the PZT patch [F], :math:`K^T_3 \varepsilon_0 L_p b / t_c`.

    The free permittivity :math:`\varepsilon^T` is what a capacitance meter sees on an
    unbonded patch; bonded to the beam the patch is partly clamped and its capacitance
    lower, by at most the factor :math:`1 - k_{31}^2` = 0.87 (APC 850: :math:`k_{31}` =
    0.36), within the datasheet's +/-20 % tolerance.

    Parameters
    ----------
    params : BeamParameters, optional
        Geometry of the patch (``patch_length``, ``width``, ``pzt_thickness``); default:
        the default parameters (the thesis's MATLAB values).
    relative_permittivity : float
        :math:`K^T_3` [-], > 0 (default :data:`PZT_PERMITTIVITY`).

    Returns
    -------
    float
        The capacitance [F] (22.7 nF for the default parameters).
    """
    p = BeamParameters() if params is None else params
    if not isinstance(p, BeamParameters):
        raise ValueError(f"params must be a BeamParameters or None, got {params!r}")
    k = check_real("relative_permittivity", relative_permittivity, 0.0, low_open=True)
    if p.patch_length == 0:
        raise ValueError("params: a bare beam (patch_length = 0) has no patch, so no capacitance")
    return k * EPSILON_0 * p.patch_length * p.width / p.pzt_thickness


def slew_rate(current: float, capacitance: float) -> float:
    """The largest rate of change [V/s] of a capacitive load's voltage for a current limit
    ``current`` [A]: ``current / capacitance``."""
    return float(current) / float(capacitance)


#: The reference amplifier's slew rate on the patch [V/s] (module docstring).
REFERENCE_SLEW_RATE = slew_rate(REFERENCE_CURRENT, patch_capacitance())


def with_amplifier(
    A: np.ndarray, B: np.ndarray, E: np.ndarray, bandwidth: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""The plant ``(A, B, E)`` (voltage input B, load input E) driven through a first-order
    amplifier of ``bandwidth`` [Hz]: the state gains the patch voltage :math:`V_p`,
    :math:`\dot V_p = \omega_a (V_c - V_p)`, :math:`\omega_a = 2\pi f_a`, and the input is
    the command :math:`V_c`:

    .. math::

        \frac{d}{dt}\begin{bmatrix} x \\ V_p \end{bmatrix} =
        \begin{bmatrix} A & B \\ 0 & -\omega_a \end{bmatrix}
        \begin{bmatrix} x \\ V_p \end{bmatrix} +
        \begin{bmatrix} 0 \\ \omega_a \end{bmatrix} V_c +
        \begin{bmatrix} E \\ 0 \end{bmatrix} f .

    Linear, so sampled exactly like the plant (zero-order hold on :math:`V_c`)."""
    n = A.shape[0]
    w = 2.0 * np.pi * float(bandwidth)
    Aa = np.zeros((n + 1, n + 1))
    Aa[:n, :n] = A
    Aa[:n, n] = B[:, 0]
    Aa[n, n] = -w
    Ba = np.zeros((n + 1, 1))
    Ba[n, 0] = w
    Ea = np.zeros((n + 1, 1))
    Ea[:n] = E
    return Aa, Ba, Ea
