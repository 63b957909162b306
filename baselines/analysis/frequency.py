r"""Frequency response of the tip to the load, measured with a periodic multisine.

The excitation is a multisine: a period of :math:`N_p` control periods (frequency
resolution :math:`\Delta\omega = 2\pi / (N_p \Delta)`), every DFT line from
:data:`LOW` to :data:`HIGH_FRACTION` of the Nyquist frequency at equal amplitude, with
Schroeder's phases :math:`\varphi_j = -\pi j (j - 1) / J` (a low crest factor for a flat
spectrum; Schroeder 1970). It is held over each control period (the load the env
integrates) and repeated: the first period lets the transients die out, and the response
is read on the last one, where it is periodic, as :math:`H(e^{i\omega_j\Delta}) =
Y_j / F_j` (DFT lines of the tip and the load over the same period). The estimate is the
sampled compliance from a load held over each period, the same for the passive beam and
the closed loop, so ratios of the two are free of the hold's own roll-off.

**Transients.** A mode of decay rate :math:`\zeta\omega` leaves a fraction
:math:`e^{-\zeta\omega N_p \Delta}` of its transient in the last period
(:func:`transient_residual`): with the default resolution, 5.6e-7 for the passive beam's
least damped mode (mode 2, :math:`\zeta\omega` = 1.15 1/s).

**Peaks.** Near an isolated resonance :math:`1/|H|^2` is a parabola in :math:`\omega`, so
the peak of a band is read from the three lines around the largest one
(:func:`band_peak`): exact for one lightly damped mode, whatever the lines' offset from
the resonance, where the largest line alone is low by up to
:math:`1/\sqrt{1 + (\Delta\omega / 2\zeta\omega)^2}`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from acld_gym.util.validate import check_int, check_real

__all__ = [
    "Multisine",
    "multisine",
    "frequency_response",
    "band_peak",
    "transient_residual",
    "LOW",
    "HIGH_FRACTION",
    "RESOLUTION",
]

#: Lowest excited frequency [rad/s] (below mode 1, 177 rad/s).
LOW = 20.0
#: Highest excited frequency, as a fraction of the Nyquist frequency.
HIGH_FRACTION = 0.98
#: Default line spacing [rad/s].
RESOLUTION = 0.5


@dataclass(frozen=True)
class Multisine:
    """A periodic multisine on the DFT lines ``bins`` of a period of ``n_period`` steps."""

    n_period: int
    bins: np.ndarray
    dt: float

    @property
    def frequencies(self) -> np.ndarray:
        """The excited frequencies [rad/s]."""
        return self.bins * (2.0 * np.pi / (self.n_period * self.dt))

    @property
    def resolution(self) -> float:
        """Line spacing [rad/s]."""
        return 2.0 * np.pi / (self.n_period * self.dt)

    def period(self) -> np.ndarray:
        """One period, unit RMS (Schroeder phases)."""
        j = np.arange(1, self.bins.size + 1)
        spectrum = np.zeros(self.n_period // 2 + 1, dtype=complex)
        spectrum[self.bins] = np.exp(-1j * np.pi * j * (j - 1) / self.bins.size)
        x = np.fft.irfft(spectrum, self.n_period)
        return x / np.sqrt(np.mean(x**2))

    def signal(self, rms: float, periods: int = 2) -> np.ndarray:
        """``periods`` periods of load [N] with RMS ``rms`` [N], one value per step."""
        check_real("rms", rms, 0.0)
        check_int("periods", periods, 1, 1000)
        return np.tile(rms * self.period(), periods)


def multisine(
    dt: float,
    resolution: float = RESOLUTION,
    low: float = LOW,
    high_fraction: float = HIGH_FRACTION,
) -> Multisine:
    """Every DFT line from ``low`` [rad/s] to ``high_fraction`` of the Nyquist frequency
    for a period that resolves ``resolution`` [rad/s] (rounded to whole steps)."""
    check_real("dt", dt, 0.0, low_open=True, unit="s")
    check_real("resolution", resolution, 0.0, low_open=True, unit="rad/s")
    check_real("high_fraction", high_fraction, 0.0, 1.0, low_open=True)
    n = int(round(2.0 * np.pi / (resolution * dt)))
    dw = 2.0 * np.pi / (n * dt)
    j0 = max(1, int(np.ceil(check_real("low", low, 0.0, unit="rad/s") / dw)))
    j1 = min(int(np.floor(high_fraction * np.pi / dt / dw)), n // 2 - 1)
    if j1 < j0:
        raise ValueError(
            f"low: no DFT line between {low:g} rad/s and {high_fraction:g} of the Nyquist frequency"
        )
    return Multisine(n_period=n, bins=np.arange(j0, j1 + 1), dt=float(dt))


def frequency_response(ms: Multisine, load: np.ndarray, y: np.ndarray) -> np.ndarray:
    """:math:`Y_j / F_j` on the excited lines, from the last whole period of the run
    (``load[k]`` over period k, ``y[k]`` the tip at t = k dt, ``y`` one longer)."""
    n = ms.n_period
    periods = load.size // n
    if periods < 2 or y.size != load.size + 1:
        raise ValueError(
            f"load must hold at least two periods of {n} steps and y one more "
            f"sample, got {load.size} and {y.size}"
        )
    k = (periods - 1) * n
    F = np.fft.rfft(load[k : k + n])[ms.bins]
    Y = np.fft.rfft(y[k : k + n])[ms.bins]
    return Y / F


def band_peak(omega: np.ndarray, H: np.ndarray, low: float, high: float) -> tuple[float, float]:
    """``(peak |H|, its frequency)`` in [low, high) (module docstring: the parabola of
    1/|H|^2 through the three lines around the largest; the largest line itself where
    that fails or at an edge of the band)."""
    inside = np.flatnonzero((omega >= low) & (omega < high))
    if inside.size == 0:
        raise ValueError(f"no line between {low:g} and {high:g} rad/s")
    mag = np.abs(H)
    i = inside[np.argmax(mag[inside])]
    if i - 1 not in inside or i + 1 not in inside:
        return float(mag[i]), float(omega[i])
    q = 1.0 / mag[i - 1 : i + 2] ** 2
    step = omega[i + 1] - omega[i]
    curv = q[2] - 2.0 * q[1] + q[0]
    if curv <= 0:
        return float(mag[i]), float(omega[i])
    shift = 0.5 * (q[0] - q[2]) / curv
    qmin = q[1] - 0.125 * (q[2] - q[0]) ** 2 / curv
    if abs(shift) > 1.0 or qmin <= 0:
        return float(mag[i]), float(omega[i])
    return float(1.0 / np.sqrt(qmin)), float(omega[i] + shift * step)


def transient_residual(decay_rates, ms: Multisine) -> float:
    """:math:`\\max e^{-\\sigma N_p \\Delta}` over the decay rates :math:`\\sigma` [1/s]: the
    fraction of a transient left in the period that is read."""
    sigma = np.asarray(decay_rates, dtype=float)
    return float(np.exp(-np.min(sigma) * ms.n_period * ms.dt)) if sigma.size else 0.0
