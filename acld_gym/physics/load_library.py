r"""The excitation library: band-limited random force (:func:`band_limited_noise`), sine
sweep (:func:`sine_sweep`), half-sine shock (:func:`half_sine_shock`) and a recorded
signal (:func:`recorded_load`), each a :class:`acld_gym.physics.load_components.TipLoad`.
Public face: :mod:`acld_gym.physics.loads`.
"""

from __future__ import annotations

import numpy as np

from .load_components import Harmonic, Samples, TipLoad, _finite

__all__ = ["band_limited_noise", "sine_sweep", "half_sine_shock", "recorded_load"]


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
    # scipy.signal (a core dependency) costs about 0.4 s to import and only this generator
    # needs it: imported here so that `import acld_gym` does not pay for it
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
