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

The parts: the load's model in :mod:`acld_gym.physics.load_components`, the named cases and
the random mix in :mod:`acld_gym.physics.load_cases`, the excitation library in
:mod:`acld_gym.physics.load_library`; every name is importable from here.
"""

from __future__ import annotations

from .load_cases import (
    LOAD_CASES,
    RANDOM,
    THESIS_CASES,
    case_label,
    case_load,
    check_load_case,
    parse_load_case,
    random_load,
    thesis_load,
)
from .load_components import Harmonic, LoadPiece, Pulse, Samples, TipLoad
from .load_library import band_limited_noise, half_sine_shock, recorded_load, sine_sweep

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
