r"""The named load cases: :data:`LOAD_CASES`, the one registry of the names accepted
wherever a load case is chosen (the envs' ``load_case``, ``reset(options=...)``, the
training configs and the evaluators; :func:`check_load_case`, :func:`parse_load_case`),
the thesis's three (:func:`thesis_load`) and the per-episode random mix
(:func:`random_load`). Public face: :mod:`acld_gym.physics.loads`.
"""

from __future__ import annotations

import numpy as np

from .load_components import Harmonic, Pulse, Samples, TipLoad

__all__ = [
    "thesis_load",
    "THESIS_CASES",
    "RANDOM",
    "LOAD_CASES",
    "check_load_case",
    "parse_load_case",
    "case_load",
    "case_label",
    "random_load",
]

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
