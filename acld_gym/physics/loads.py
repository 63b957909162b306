r"""Tip loads: rectangular pulses and switched harmonics (thesis ch. 5).

A :class:`TipLoad` is a sum of components. Between consecutive breakpoints
(pulse and harmonic edges) it equals a constant plus a sum of sinusoids,
which is what the exact integrators in :mod:`acld_gym.design.simulate` need:
:meth:`TipLoad.piece` returns that representation for an interval.

The three thesis cases (:func:`thesis_load`):

1. 1 N for 1 ms at t = 0;
2. the same plus a second 1 ms, 1 N pulse at t = 0.100 s;
3. :math:`0.1 \sin(179 t)` N for 0.193 s (5.5 cycles, ends at f = 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Pulse", "Harmonic", "Samples", "TipLoad", "thesis_load", "THESIS_CASES", "LoadPiece"]


@dataclass(frozen=True)
class Pulse:
    """Rectangular pulse: ``amplitude`` [N] on [``start``, ``start + duration``) [s]."""

    start: float
    duration: float
    amplitude: float

    def __post_init__(self):
        if not self.duration > 0:
            raise ValueError(f"Pulse.duration must be positive [s], got {self.duration!r}")
        if not np.isfinite(self.start) or not np.isfinite(self.amplitude):
            raise ValueError("Pulse.start and Pulse.amplitude must be finite")

    @property
    def end(self) -> float:
        return self.start + self.duration


@dataclass(frozen=True)
class Harmonic:
    """``amplitude * sin(frequency * (t - start) + phase)`` [N] on [start, start + duration)."""

    amplitude: float
    frequency: float
    start: float
    duration: float
    phase: float = 0.0

    def __post_init__(self):
        if not self.duration > 0:
            raise ValueError(f"Harmonic.duration must be positive [s], got {self.duration!r}")
        if not self.frequency > 0:
            raise ValueError(f"Harmonic.frequency must be positive [rad/s], got {self.frequency!r}")

    @property
    def end(self) -> float:
        return self.start + self.duration


@dataclass(frozen=True)
class Samples:
    """Piecewise-linear load through ``values`` [N] at ``start + i * step`` [s], zero
    outside. Used for band-limited noise; the sampled model integrates it
    exactly when ``step`` is a multiple of its sub-step (first-order hold)."""

    start: float
    step: float
    values: tuple[float, ...]

    def __post_init__(self):
        if not self.step > 0:
            raise ValueError(f"Samples.step must be positive [s], got {self.step!r}")
        if len(self.values) < 2:
            raise ValueError("Samples.values needs at least two samples")

    @property
    def end(self) -> float:
        return self.start + self.step * (len(self.values) - 1)


@dataclass(frozen=True)
class LoadPiece:
    """Load on an interval between breakpoints: ``const + sum_i amp_i sin(w_i t + ph_i)``."""

    const: float
    harmonics: tuple[tuple[float, float, float], ...]  # (amplitude, omega, phase at t = 0)


@dataclass(frozen=True)
class TipLoad:
    """A sum of pulses and harmonics applied transversely at the tip."""

    components: tuple[Pulse | Harmonic | Samples, ...] = ()

    def __call__(self, t) -> np.ndarray:
        """Load [N] at time(s) ``t`` [s]; intervals are closed on the left."""
        t = np.asarray(t, dtype=float)
        f = np.zeros_like(t)
        for c in self.components:
            on = (t >= c.start) & (t < c.end)
            if isinstance(c, Pulse):
                f = f + np.where(on, c.amplitude, 0.0)
            elif isinstance(c, Samples):
                grid = c.start + c.step * np.arange(len(c.values))
                f = f + np.where(on, np.interp(t, grid, c.values), 0.0)
            else:
                f = f + np.where(on, c.amplitude * np.sin(c.frequency * (t - c.start) + c.phase),
                                 0.0)
        return f

    def breakpoints(self) -> np.ndarray:
        """Sorted distinct edge times [s]."""
        return np.unique([e for c in self.components for e in (c.start, c.end)])

    def piece(self, t0: float, t1: float) -> LoadPiece:
        """The load on [t0, t1), which must not contain a breakpoint inside."""
        tm = 0.5 * (t0 + t1)
        const = 0.0
        harms = []
        for c in self.components:
            if not (c.start <= tm < c.end):
                continue
            if isinstance(c, Pulse):
                const += c.amplitude
            elif isinstance(c, Samples):
                raise NotImplementedError(
                    "load: the continuous simulator takes pulses and harmonics only; sample "
                    "Samples loads with acld_gym.design.discrete")
            else:
                harms.append((c.amplitude, c.frequency, c.phase - c.frequency * c.start))
        return LoadPiece(const=const, harmonics=tuple(harms))

    @property
    def harmonic_frequencies(self) -> tuple[float, ...]:
        return tuple(sorted({c.frequency for c in self.components if isinstance(c, Harmonic)}))


#: The thesis's load cases by number.
THESIS_CASES = (1, 2, 3)


def thesis_load(case: int) -> TipLoad:
    """Tip load of thesis load case 1, 2 or 3 (ch. 5)."""
    if case == 1:
        return TipLoad((Pulse(0.0, 1e-3, 1.0),))
    if case == 2:
        return TipLoad((Pulse(0.0, 1e-3, 1.0), Pulse(0.1, 1e-3, 1.0)))
    if case == 3:
        return TipLoad((Harmonic(0.1, 179.0, 0.0, 0.193),))
    raise ValueError(f"case must be one of {THESIS_CASES}, got {case!r}")
