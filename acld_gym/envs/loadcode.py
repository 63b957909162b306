"""Tip loads encoded as numbers, for the compiled step (``acld_gym.envs._stepcore``).

The compiled step evaluates each env's :class:`acld_gym.physics.loads.TipLoad` at the
period's sub-step points itself, instead of reading a table tabulated at reset: a reset then
costs an encoding (a few numbers per component) instead of a pass over the whole episode.
The C code evaluates components with the same time points, comparisons and sums as
:meth:`TipLoad.__call__` and :func:`acld_gym.envs.step.load_schedule` (harmonics with the C
library's ``sin``, so the loads agree with numpy's to round-off).

Layout of :class:`LoadCodes` (the one owner): per env a row of ``comp`` (K, 8: one cache line
per component) -- ``[type, start, end, p0, p1, p2, p3, p4]``, with type 1 a pulse (p0 its
amplitude), 2 a harmonic (amplitude, frequency, phase) and 3 samples (step, offset of the
values in the env's row of ``pool``, count, and two slots in which the compiled step keeps
its last segment and that segment's slope: 0 and NaN when encoded) -- and ``ncomp``, the
components in use.
"""

from __future__ import annotations

import numpy as np

from acld_gym.physics.loads import Harmonic, Pulse, Samples, TipLoad

__all__ = ["LoadCodes", "PULSE", "HARMONIC", "SAMPLES", "WIDTH"]

PULSE, HARMONIC, SAMPLES = 1, 2, 3
#: Numbers per encoded component.
WIDTH = 8


class LoadCodes:
    """The encoded loads of N envs (grows its arrays when a load needs more room;
    :attr:`version` counts the reallocations, after which the compiled step must be given
    the new arrays)."""

    def __init__(self, n: int, components: int = 8, samples: int = 512):
        self.comp = np.zeros((n, components, WIDTH))
        self.ncomp = np.zeros(n, dtype=np.int64)
        self.pool = np.zeros((n, samples))
        self.version = 0

    def _grow(self, components: int, samples: int) -> None:
        n, K, _ = self.comp.shape
        if components > K:
            comp = np.zeros((n, max(components, 2 * K), WIDTH))
            comp[:, :K] = self.comp
            self.comp = comp
        P = self.pool.shape[1]
        if samples > P:
            pool = np.zeros((n, max(samples, 2 * P)))
            pool[:, :P] = self.pool
            self.pool = pool
        self.version += 1

    def set(self, i: int, load: TipLoad) -> None:
        """Encode ``load`` as env ``i``'s."""
        comps = load.components
        n_samples = sum(len(c.values) for c in comps if isinstance(c, Samples))
        if len(comps) > self.comp.shape[1] or n_samples > self.pool.shape[1]:
            self._grow(len(comps), n_samples)
        row, pool = self.comp[i], self.pool[i]
        offset = 0
        for j, c in enumerate(comps):
            if isinstance(c, Pulse):
                row[j] = (PULSE, c.start, c.end, c.amplitude, 0.0, 0.0, 0.0, 0.0)
            elif isinstance(c, Harmonic):
                row[j] = (HARMONIC, c.start, c.end, c.amplitude, c.frequency, c.phase, 0.0, 0.0)
            else:
                n = len(c.values)
                pool[offset : offset + n] = c.values
                row[j] = (SAMPLES, c.start, c.end, c.step, offset, n, 0.0, np.nan)
                offset += n
        self.ncomp[i] = len(comps)
