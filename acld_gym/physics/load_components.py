r"""The tip load's model: a :class:`TipLoad` is a sum of components (:class:`Pulse`,
:class:`Harmonic`, :class:`Samples`), each checked at construction.

Between consecutive breakpoints (pulse and harmonic edges) a load of pulses and harmonics
equals a constant plus a sum of sinusoids, which is what the exact integrators in
:mod:`acld_gym.design.simulate` need: :meth:`TipLoad.piece` returns that representation
(:class:`LoadPiece`) for an interval. The sampled environment takes any component (it
integrates the load linearly between its sub-steps, :mod:`acld_gym.design.discrete`).
Public face: :mod:`acld_gym.physics.loads`.
"""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass, replace

import numpy as np

__all__ = ["Pulse", "Harmonic", "Samples", "TipLoad", "LoadPiece"]


def _finite(cls: str, names: str, *values) -> None:
    """``ValueError`` unless every value is a finite real number (not a bool); ``names``
    are their names, comma-separated (for the message)."""
    try:
        ok = all(map(math.isfinite, values)) and not any(type(v) is bool for v in values)
    except TypeError:
        ok = False
    if not ok:
        for name, value in zip(names.split(", "), values, strict=True):
            if (
                type(value) is bool
                or not isinstance(value, (int, float, np.floating, np.integer))
                or not math.isfinite(value)
            ):
                raise ValueError(f"{cls}.{name} must be a finite real number, got {value!r}")


@dataclass(frozen=True)
class Pulse:
    """Rectangular pulse: ``amplitude`` [N] on [``start``, ``start + duration``) [s]."""

    start: float
    duration: float
    amplitude: float

    def __post_init__(self):
        _finite("Pulse", "start, duration, amplitude", self.start, self.duration, self.amplitude)
        if not self.duration > 0:
            raise ValueError(f"Pulse.duration must be positive [s], got {self.duration!r}")

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
        _finite("Harmonic", "amplitude, frequency, start, duration, phase", *astuple(self))
        if not self.duration > 0:
            raise ValueError(f"Harmonic.duration must be positive [s], got {self.duration!r}")
        if not self.frequency > 0:
            raise ValueError(f"Harmonic.frequency must be positive [rad/s], got {self.frequency!r}")

    @property
    def end(self) -> float:
        return self.start + self.duration


@dataclass(frozen=True, eq=False)
class Samples:
    """Piecewise-linear load through ``values`` [N] at ``start + i * step`` [s], zero
    outside. Used for band-limited noise and recorded signals; the sampled model
    integrates it exactly when ``step`` is a multiple of its sub-step (first-order hold).
    ``values`` (any sequence of at least two finite real numbers) is kept as a read-only
    float64 array; two Samples are equal when start, step and every value are."""

    start: float
    step: float
    values: np.ndarray

    def __post_init__(self):
        _finite("Samples", "start, step", self.start, self.step)
        if not self.step > 0:
            raise ValueError(f"Samples.step must be positive [s], got {self.step!r}")
        values = self.values
        if isinstance(values, np.ndarray):
            ok = values.dtype.kind in "iuf"
        else:
            try:
                ok = not any(type(v) is bool for v in values)
            except TypeError:
                ok = False
        try:
            arr = np.array(values, dtype=float) if ok else None
        except (TypeError, ValueError):
            arr = None
        if arr is None or arr.ndim != 1:
            raise ValueError("Samples.values must be a 1-D sequence of real numbers [N]")
        if arr.size < 2:
            raise ValueError("Samples.values needs at least two samples")
        if not np.isfinite(arr).all():
            raise ValueError("Samples.values must be finite real numbers [N]")
        arr.flags.writeable = False
        object.__setattr__(self, "values", arr)

    def __eq__(self, other) -> bool:
        if not isinstance(other, Samples):
            return NotImplemented
        return (
            self.start == other.start
            and self.step == other.step
            and np.array_equal(self.values, other.values)
        )

    def __hash__(self) -> int:
        return hash((self.start, self.step, self.values.tobytes()))

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
    """A sum of pulses, harmonics and sampled records applied transversely at the tip."""

    components: tuple[Pulse | Harmonic | Samples, ...] = ()

    def __post_init__(self):
        if not isinstance(self.components, tuple) or not all(
            type(c) in (Pulse, Harmonic, Samples) for c in self.components
        ):
            raise ValueError(
                "TipLoad.components must be a tuple of Pulse, Harmonic and Samples, "
                f"got {self.components!r}"
            )

    def scaled(self, factor: float) -> TipLoad:
        """The same load times ``factor`` (every amplitude and sample scaled)."""
        _finite("TipLoad.scaled", "factor", factor)
        out = []
        for c in self.components:
            if isinstance(c, Samples):
                out.append(Samples(c.start, c.step, factor * c.values))
            else:  # a pulse or a harmonic
                out.append(replace(c, amplitude=factor * c.amplitude))
        return TipLoad(tuple(out))

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
                f = f + np.where(
                    on, c.amplitude * np.sin(c.frequency * (t - c.start) + c.phase), 0.0
                )
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
                    "Samples loads with acld_gym.design.discrete"
                )
            else:
                harms.append((c.amplitude, c.frequency, c.phase - c.frequency * c.start))
        return LoadPiece(const=const, harmonics=tuple(harms))

    @property
    def harmonic_frequencies(self) -> tuple[float, ...]:
        return tuple(sorted({c.frequency for c in self.components if isinstance(c, Harmonic)}))
