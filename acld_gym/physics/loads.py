r"""Tip loads: pulses, switched harmonics and sampled records; the named load cases; an
excitation library.

A :class:`TipLoad` is a sum of components (:class:`Pulse`, :class:`Harmonic`,
:class:`Samples`). Between consecutive breakpoints (pulse and harmonic edges) a load of
pulses and harmonics equals a constant plus a sum of sinusoids, which is what the exact
integrators in :mod:`acld_gym.design.simulate` need: :meth:`TipLoad.piece` returns that
representation for an interval. The sampled environment takes any component (it
integrates the load linearly between its sub-steps, :mod:`acld_gym.design.discrete`).

**Named load cases** (:data:`LOAD_CASES`, the one registry of the names accepted wherever
a load case is chosen: the envs' ``load_case``, ``reset(options=...)``, the training
configs and the evaluators; :func:`check_load_case`, :func:`parse_load_case`):

1. 1 N for 1 ms at t = 0 (thesis ch. 5);
2. the same plus a second 1 ms, 1 N pulse at t = 0.100 s;
3. :math:`0.1 \sin(179 t)` N for 0.193 s (5.5 cycles, ends at f = 0);

``"random"``: a new :func:`random_load` per episode. A :class:`TipLoad` is accepted
wherever a case is (a custom load).

**Excitation library** (each returns a :class:`TipLoad`): :func:`band_limited_noise` (a
band-limited random force), :func:`sine_sweep`, :func:`half_sine_shock` and
:func:`recorded_load` (a recorded signal from an array).
"""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass, replace

import numpy as np

__all__ = [
    "Pulse",
    "Harmonic",
    "Samples",
    "TipLoad",
    "LoadPiece",
    "thesis_load",
    "THESIS_CASES",
    "RANDOM",
    "LOAD_CASES",
    "check_load_case",
    "parse_load_case",
    "case_load",
    "case_label",
    "random_load",
    "band_limited_noise",
    "sine_sweep",
    "half_sine_shock",
    "recorded_load",
]


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


#: What evaluates a load (the compiled step and the simulators read ``components`` alone).
_EVALUATION = ("__call__", "piece", "breakpoints", "scaled", "harmonic_frequencies", "components")
#: The thesis's load cases by number.
THESIS_CASES = (1, 2, 3)
#: The name of the per-episode random load (:func:`random_load`).
RANDOM = "random"
#: Every named load case: the thesis's three and the random mix.
LOAD_CASES = THESIS_CASES + (RANDOM,)


def thesis_load(case: int) -> TipLoad:
    """Tip load of thesis load case 1, 2 or 3 (ch. 5)."""
    if case == 1 and type(case) is int:
        return TipLoad((Pulse(0.0, 1e-3, 1.0),))
    if case == 2 and type(case) is int:
        return TipLoad((Pulse(0.0, 1e-3, 1.0), Pulse(0.1, 1e-3, 1.0)))
    if case == 3 and type(case) is int:
        return TipLoad((Harmonic(0.1, 179.0, 0.0, 0.193),))
    raise ValueError(f"case must be one of {THESIS_CASES}, got {case!r}")


def check_load_case(value, name: str = "load_case"):
    """``value`` if it is a named case (:data:`LOAD_CASES`; a Python or numpy integer 1-3 is
    returned as ``int``) or a :class:`TipLoad` (a subclass that overrides none of
    :data:`_EVALUATION`: every consumer evaluates a load from its components); else
    ``ValueError`` naming ``name``."""
    if isinstance(value, TipLoad):
        over = sorted(m for m in _EVALUATION if getattr(type(value), m) is not getattr(TipLoad, m))
        if over:
            raise ValueError(
                f"{name}: a TipLoad subclass may not override {', '.join(over)} (a load is "
                f"evaluated from its components alone), got {type(value).__name__}"
            )
        TipLoad.__post_init__(value)  # its components, even if its __post_init__ skipped them
        return value
    if (
        isinstance(value, (int, np.integer))
        and not isinstance(value, (bool, np.bool_))
        and int(value) in THESIS_CASES
    ):
        return int(value)
    if isinstance(value, str) and value == RANDOM:
        return RANDOM
    raise ValueError(f"{name} must be one of {list(LOAD_CASES)} or a TipLoad, got {value!r}")


def parse_load_case(value) -> int | str:
    """A named load case from YAML or command-line text: 1, 2, 3 (int or digit string) or
    ``"random"``; anything else raises a ``ValueError`` naming the choices."""
    if isinstance(value, str) and value in tuple(str(c) for c in THESIS_CASES):
        return int(value)
    if type(value) in (int, str) and value in LOAD_CASES:  # not bool, not 1.0
        return value
    raise ValueError(
        f"load case must be {', '.join(map(str, THESIS_CASES))} or {RANDOM!r}, got {value!r}"
    )


def case_load(case) -> TipLoad | None:
    """The fixed load of a case: a thesis case's :func:`thesis_load`, a :class:`TipLoad`
    itself, None for ``"random"`` (drawn per episode)."""
    case = check_load_case(case)
    if isinstance(case, TipLoad):
        return case
    return None if case == RANDOM else thesis_load(case)


def case_label(case) -> str:
    """A short label of a case for tables: ``"1"``, ``"random"``, ``"custom"``."""
    case = check_load_case(case)
    return "custom" if isinstance(case, TipLoad) else str(case)


# --- the random mix ------------------------------------------------------------------------
_BOX = np.ones(4) / 2.0  # the noise's moving sum (times 1/2)


def random_load(
    rng: np.random.Generator,
    duration: float,
    grid: float,
    modes: tuple[float, float] = (179.0, 1115.0),
) -> TipLoad:
    """A bounded random tip load drawn from ``rng`` (the ``"random"`` case).

    Always one to three pulses (amplitude U(-1.5, 1.5) N, width 0.5-3 ms,
    start in the first 70 % of the episode); with probability 1/2 a harmonic
    of amplitude up to 0.08 N within +/-5 % of the plant's first (probability 0.7)
    or second natural frequency ``modes`` [rad/s], 0.05-0.3 s long; with
    probability 1/2 band-limited noise (low-pass random samples every 2 ms, std
    about 0.05 N). Pulse edges lie on ``grid`` [s] (the env's load sub-step), so
    the sampled model integrates them exactly.

    The draws, in this order: the number of pulses (``integers``); per pulse its start,
    width and amplitude; a coin for the harmonic and, if it comes up, a coin for the mode
    and its amplitude, frequency, start, duration and phase; a coin for the noise and, if
    it comes up, its white samples. ``U(a, b)`` is ``a + (b - a) u`` with u the
    generator's next double, which is what ``Generator.uniform(a, b)`` computes; the
    uniform doubles are drawn in blocks (``Generator.random(n)`` gives the same stream as
    n single draws), so the numbers are those of one ``uniform`` call per value.
    """
    comps: list = []
    n_pulses = int(rng.integers(1, 4))
    u = rng.random(3 * n_pulses + 1).tolist()
    for p in range(n_pulses):
        a, b, c = u[3 * p : 3 * p + 3]
        start = round((0.7 * duration) * a / grid) * grid
        width = max(round((5e-4 + (3e-3 - 5e-4) * b) / grid), 1) * grid
        comps.append(Pulse(float(start), float(width), -1.5 + 3.0 * c))
    if u[-1] < 0.5:
        m, a, w, s, d, ph, noise_coin = rng.random(7).tolist()
        w0 = modes[0] if m < 0.7 else modes[1]
        comps.append(
            Harmonic(
                0.08 * a,
                w0 * (0.95 + (1.05 - 0.95) * w),
                (0.5 * duration) * s,
                0.05 + (0.3 - 0.05) * d,
                (2 * np.pi) * ph,
            )
        )
    else:
        noise_coin = float(rng.random())
    if noise_coin < 0.5:
        step = max(round(2e-3 / grid), 1) * grid
        n = int(duration / step) + 1
        white = rng.normal(0.0, 1.0, n)
        smooth = np.convolve(white, _BOX, mode="same")  # ~0.25 kHz low-pass
        comps.append(Samples(0.0, float(step), 0.05 * smooth))
    return TipLoad(tuple(comps))


# --- excitation library --------------------------------------------------------------------
def _check_positive(name: str, value) -> float:
    _finite("load", name, value)
    if not value > 0:
        raise ValueError(f"{name} must be positive, got {value!r}")
    return float(value)


def band_limited_noise(
    rng: np.random.Generator,
    duration: float,
    std: float,
    cutoff: float,
    step: float = 1e-4,
    start: float = 0.0,
    order: int = 4,
) -> TipLoad:
    """A band-limited random force: white Gaussian samples every ``step`` [s] over
    ``duration`` [s], low-passed at ``cutoff`` [Hz] by an ``order``-th order Butterworth
    filter run forward and backward (zero phase, :func:`scipy.signal.sosfiltfilt`), scaled
    to the sample standard deviation ``std`` [N]; linear between the samples. ``cutoff``
    must lie below the Nyquist frequency ``1 / (2 step)``."""
    from scipy.signal import butter, sosfiltfilt

    duration, std, step = (
        _check_positive(n, v) for n, v in (("duration", duration), ("std", std), ("step", step))
    )
    cutoff = _check_positive("cutoff", cutoff)
    if not cutoff < 0.5 / step:
        raise ValueError(
            f"cutoff must be below the Nyquist frequency 1/(2 step) = "
            f"{0.5 / step:g} Hz, got {cutoff!r}"
        )
    n = int(round(duration / step)) + 1
    if n < 3 * (2 * order + 1):
        raise ValueError(
            f"duration must hold at least {3 * (2 * order + 1)} samples of "
            f"step {step:g} s for the filter, got {duration!r}"
        )
    sos = butter(order, cutoff, fs=1.0 / step, output="sos")
    x = sosfiltfilt(sos, rng.normal(0.0, 1.0, n))
    x *= std / float(np.std(x))
    return TipLoad((Samples(float(start), step, x),))


def sine_sweep(
    amplitude: float,
    f_start: float,
    f_stop: float,
    duration: float,
    start: float = 0.0,
    step: float = 1e-4,
    spacing: str = "linear",
) -> TipLoad:
    r"""A sine sweep (chirp) ``amplitude sin(phi(t))`` [N] from ``f_start`` to ``f_stop``
    [Hz] over ``duration`` [s], starting at ``start`` [s]:
    :math:`\phi = 2\pi (f_0 \tau + (f_1 - f_0) \tau^2 / 2T)` (``"linear"``) or
    :math:`2\pi f_0 T (k^{\tau/T} - 1) / \ln k`, :math:`k = f_1 / f_0` (``"log"``),
    :math:`\tau = t - t_0`. Sampled every ``step`` [s] and linear in between: the
    interpolation error is about :math:`(2\pi f h)^2 / 8` of the amplitude at frequency f,
    so ``step`` must be at most ``1 / (20 max(f_start, f_stop))`` (error < 1.3 %)."""
    _finite("sine_sweep", "amplitude, start", amplitude, start)
    f0, f1, T, step = (
        _check_positive(n, v)
        for n, v in (
            ("f_start", f_start),
            ("f_stop", f_stop),
            ("duration", duration),
            ("step", step),
        )
    )
    if spacing not in ("linear", "log"):
        raise ValueError(f"spacing must be 'linear' or 'log', got {spacing!r}")
    if step > 1.0 / (20.0 * max(f0, f1)):
        raise ValueError(
            f"step must be at most 1/(20 max(f_start, f_stop)) = "
            f"{1.0 / (20.0 * max(f0, f1)):g} s, got {step!r}"
        )
    tau = np.arange(int(round(T / step)) + 1) * step
    if spacing == "linear":
        phi = 2 * np.pi * (f0 * tau + (f1 - f0) * tau**2 / (2 * T))
    elif f0 == f1:
        phi = 2 * np.pi * f0 * tau
    else:
        k = f1 / f0
        phi = 2 * np.pi * f0 * T * (k ** (tau / T) - 1.0) / np.log(k)
    return TipLoad((Samples(float(start), step, amplitude * np.sin(phi)),))


def half_sine_shock(amplitude: float, duration: float, start: float = 0.0) -> TipLoad:
    """A half-sine shock pulse ``amplitude sin(pi (t - start) / duration)`` [N] on
    [``start``, ``start + duration``) [s] (the classical shock-test pulse): one
    :class:`Harmonic` of frequency ``pi / duration`` [rad/s], integrated exactly by the
    continuous simulator too."""
    duration = _check_positive("duration", duration)
    return TipLoad((Harmonic(float(amplitude), np.pi / duration, float(start), duration),))


def recorded_load(values, step: float, start: float = 0.0) -> TipLoad:
    """A recorded force signal: ``values`` [N] (a 1-D array of at least two finite numbers)
    sampled every ``step`` [s] from ``start`` [s], linear in between and zero outside."""
    step = _check_positive("step", step)
    arr = np.asarray(values)
    if arr.ndim != 1 or arr.dtype.kind not in "iuf":
        raise ValueError(
            f"values must be a 1-D array of real numbers [N], got shape {arr.shape} of {arr.dtype}"
        )
    return TipLoad((Samples(float(start), step, arr),))
