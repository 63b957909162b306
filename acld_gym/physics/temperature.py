r"""Temperature of the viscoelastic layer: time-temperature superposition of its GHM modulus.

The VEM's shear modulus is the thesis's GHM model (eq. 20, one mini-oscillator):

.. math::

    G(s) = \kappa \Big[1 + \alpha \frac{s^2 + 2\zeta\hat\omega s}
                              {s^2 + 2\zeta\hat\omega s + \hat\omega^2}\Big].

A thermorheologically simple polymer follows **time-temperature superposition**: at a
temperature T its modulus is the reference curve at the *reduced frequency*
:math:`a_T \omega`, :math:`G(j\omega, T) = G_{ref}(j a_T \omega)`. In the GHM form that is
the same model with :math:`\hat\omega(T) = \hat\omega_{ref} / a_T` (κ, α and ζ unchanged;
the vertical shift :math:`\rho T / \rho_0 T_0`, under 3 % here, is neglected, as is usual
for damping polymers). Hotter (:math:`a_T < 1`) moves the transition to higher frequencies,
so at a given frequency the polymer is softer and, past its transition, less lossy.

**Shift factor.** The Williams-Landel-Ferry equation with the "universal" constants of
amorphous polymers above their glass transition (Williams, Landel & Ferry, *J. Am. Chem.
Soc.* 77 (1955) 3701-3707; Ferry, *Viscoelastic Properties of Polymers*, 3rd ed., Wiley
1980, ch. 11), :math:`C_1 = 17.44`, :math:`C_2 = 51.6` K, referred to the glass transition
:math:`T_g`:

.. math::

    \log_{10} a_T = -\frac{C_1 (T - T_g)}{C_2 + T - T_g}.

Constrained-layer damping polymers such as 3M's ISD-112 are acrylic (3M Technical Data,
"3M Viscoelastic Damping Polymers 112 and 130", October 2012), amorphous and used just
above their transition, where WLF holds.

**Reference temperature and T_g.** The thesis does not state the temperature at which its
GHM parameters hold (kappa = 1 MPa, alpha = 1, omega = 1000 rad/s, zeta = 4; Table 1); they
are taken as room-temperature values, :data:`T_REF` = 20 °C. Their material loss factor
:math:`\eta = G''/G'` peaks at :data:`LOSS_PEAK_HZ` = 14.2 Hz (0.358). :math:`T_g` follows
from the usual dynamic-mechanical convention that at :math:`T_g` the loss peak lies at
1 Hz: WLF then puts it at 14.2 Hz 3.65 K higher, so :data:`T_GLASS` = 16.35 °C -- a
room-temperature damping polymer, as ISD-112 is. (Only the shift relative to T_REF enters
the model: :func:`log_shift`.)

Range: :data:`TEMPERATURE_RANGE` = 16.5-40 °C, from the glass transition (rounded up), where
WLF starts to hold, to the rubbery plateau. Across it the GHM frequency moves from 1.2
decades below its reference to 4.3 above, which covers the transition at the beam's
frequencies: at 16.5 °C the polymer is glassy there, above 30 °C rubbery, and the plant no
longer changes (mode 1: 178.1 and 175.5 rad/s; 177.4 at T_REF, where its damping is near
its peak). Below T_g a glassy polymer follows an Arrhenius law instead; the GHM fit would
also stiffen the beam slightly with heat there (its storage modulus overshoots its glassy
value by 0.6 % at 3000 rad/s, which mode 1 reaches at 16.1 °C).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from acld_gym.physics.params import BeamParameters
from acld_gym.util.validate import check_real

__all__ = [
    "T_REF",
    "T_GLASS",
    "WLF_C1",
    "WLF_C2",
    "LOSS_PEAK_HZ",
    "TEMPERATURE_RANGE",
    "log_shift",
    "shift_factor",
    "shifted_parameters",
    "ghm_modulus",
    "check_temperature",
]

#: WLF "universal" constants (Williams, Landel & Ferry 1955): C1 [-] and C2 [K] at T_g.
WLF_C1 = 17.44
WLF_C2 = 51.6
#: Temperature at which the thesis's GHM parameters hold [°C] (module docstring).
T_REF = 20.0


def ghm_modulus(params: BeamParameters, omega) -> np.ndarray:
    """The GHM shear modulus ``G(j omega)`` [Pa] of ``params`` at ``omega`` [rad/s]."""
    s = 1j * np.asarray(omega, dtype=float)
    w, z = params.ghm_omega, params.ghm_zeta
    return params.ghm_kappa * (
        1.0 + params.ghm_alpha * (s * s + 2 * z * w * s) / (s * s + 2 * z * w * s + w * w)
    )


def _loss_peak_hz(params: BeamParameters) -> float:
    w = np.logspace(-1, 6, 70001)
    G = ghm_modulus(params, w)
    return float(w[np.argmax(G.imag / G.real)] / (2 * np.pi))


#: Frequency of the thesis GHM material's loss-factor peak at T_REF [Hz].
LOSS_PEAK_HZ = _loss_peak_hz(BeamParameters())
#: Glass transition of the polymer [°C]: where WLF puts the loss peak at 1 Hz.
T_GLASS = T_REF - WLF_C2 * math.log10(LOSS_PEAK_HZ) / (WLF_C1 - math.log10(LOSS_PEAK_HZ))
#: Accepted temperatures of the VEM [°C]: from T_g (rounded up) to 40 °C (module docstring).
TEMPERATURE_RANGE = (math.ceil(2 * T_GLASS) / 2, 40.0)


def log_shift(T: float) -> float:
    """:math:`\\log_{10}` of the shift factor at ``T`` [°C] relative to :data:`T_REF`
    (WLF about :data:`T_GLASS`); exactly 0 at T_REF."""
    if T == T_REF:
        return 0.0

    def wlf(t):
        return -WLF_C1 * (t - T_GLASS) / (WLF_C2 + t - T_GLASS)

    return wlf(T) - wlf(T_REF)


def shift_factor(T: float) -> float:
    """The shift factor :math:`a_T` [-] at ``T`` [°C] relative to :data:`T_REF` (< 1 hotter)."""
    return 10.0 ** log_shift(T)


def check_temperature(name: str, T) -> float:
    """``T`` as a float in :data:`TEMPERATURE_RANGE` [°C]; ``ValueError`` naming ``name``."""
    lo, hi = TEMPERATURE_RANGE
    return check_real(name, T, lo, hi, unit="°C")


def shifted_parameters(params: BeamParameters, T: float) -> BeamParameters:
    """``params`` with the VEM at ``T`` [°C]: the GHM frequency divided by :math:`a_T`
    (``params`` itself at :data:`T_REF`)."""
    T = check_temperature("temperature", T)
    if T == T_REF:
        return params
    return replace(params, ghm_omega=params.ghm_omega / shift_factor(T))
