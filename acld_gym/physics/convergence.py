r"""Mesh convergence of the beam model, and the thesis mesh against the converged plant.

:func:`mode_study` computes the damped modes of the same model on meshes refined
k = 1, 2, 4, ... times (every section's element count times k), fits the convergence
rate p of each mode's frequency and damping ratio from the three finest levels,

.. math::

    p = \log_2 \frac{f_{k/4} - f_{k/2}}{f_{k/2} - f_k}, \qquad
    f_\infty = f_k + \frac{f_k - f_{k/2}}{2^p - 1}

(Richardson extrapolation), and reports each level's error against :math:`f_\infty`.
The linear elements with reduced-integration shear converge at p = 2.00.

:func:`frequency_responses` evaluates the fine meshes' voltage-to-tip and
load-to-tip responses with sparse solves of :math:`(K + j\omega C - \omega^2 M) q = F`,
so that the converged plant (:mod:`acld_gym.physics.truth`) can be checked against them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from acld_gym.physics.krylov import damped_modes
from acld_gym.physics.model import first_order, parametric_model
from acld_gym.physics.params import BeamParameters, Mesh

__all__ = [
    "ModeStudy",
    "mode_study",
    "frequency_responses",
    "richardson",
    "REFINEMENTS",
    "response_grid",
    "converged_responses",
    "relative_hinf",
]

#: Refinement factors of the default study (the finest is the converged plant's mesh).
REFINEMENTS = (1, 2, 4, 8, 16, 32, 64, 128)
_DENSE_UP_TO = 8  # dense eigenvalues up to this refinement, sparse inverse iteration beyond


def richardson(
    coarse: np.ndarray, mid: np.ndarray, fine: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Fitted rate p and extrapolated limit from three levels refined by 2 each
    (module docstring); elementwise."""
    coarse, mid, fine = (np.asarray(a, dtype=float) for a in (coarse, mid, fine))
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.log2((coarse - mid) / (mid - fine))
    return p, fine + (fine - mid) / (2.0**p - 1.0)


@dataclass(frozen=True)
class ModeStudy:
    """Damped modes per refinement: ``eigenvalues[i, j]`` is mode j on refinement
    ``refinements[i]`` (:math:`\\sigma + j\\omega`, 1/s)."""

    refinements: tuple[int, ...]
    states: tuple[int, ...]
    eigenvalues: np.ndarray

    @property
    def frequencies(self) -> np.ndarray:
        """Damped natural frequencies [rad/s]."""
        return self.eigenvalues.imag

    @property
    def damping(self) -> np.ndarray:
        """Damping ratios :math:`-\\sigma / |\\lambda|`."""
        return -self.eigenvalues.real / np.abs(self.eigenvalues)

    def _fit(self, values: np.ndarray):
        return richardson(values[-3], values[-2], values[-1])

    @property
    def rate(self) -> np.ndarray:
        """Fitted convergence rate of each mode's frequency (three finest levels)."""
        return self._fit(self.frequencies)[0]

    @property
    def damping_rate(self) -> np.ndarray:
        """Fitted convergence rate of each mode's damping ratio."""
        return self._fit(self.damping)[0]

    @property
    def limit(self) -> np.ndarray:
        """Richardson-extrapolated frequencies [rad/s]."""
        return self._fit(self.frequencies)[1]

    @property
    def damping_limit(self) -> np.ndarray:
        """Richardson-extrapolated damping ratios."""
        return self._fit(self.damping)[1]

    def markdown(self) -> str:
        """The study as a Markdown table (frequencies [rad/s], errors against the limit)."""
        n = self.eigenvalues.shape[1]
        head = "| k | states | " + " | ".join(f"mode {j + 1} [rad/s]" for j in range(n)) + " |"
        rows = [head, "|---|---|" + "---|" * n]
        for k, s, f in zip(self.refinements, self.states, self.frequencies, strict=True):
            cells = [
                f"{fj:.2f} ({100 * (fj / lj - 1):+.3f} %)"
                for fj, lj in zip(f, self.limit, strict=True)
            ]
            rows.append(f"| {k} | {s} | " + " | ".join(cells) + " |")
        rows.append(
            "| limit (Richardson) | - | " + " | ".join(f"{x:.2f}" for x in self.limit) + " |"
        )
        rows.append("| fitted rate p | - | " + " | ".join(f"{x:.2f}" for x in self.rate) + " |")
        return "\n".join(rows)


def mode_study(
    n_modes: int = 4,
    refinements: tuple[int, ...] = REFINEMENTS,
    params: BeamParameters | None = None,
) -> ModeStudy:
    """The first ``n_modes`` damped modes on each refinement (a doubling sequence)."""
    refinements = tuple(int(k) for k in refinements)
    pairs = zip(refinements[:-1], refinements[1:], strict=True)
    if len(refinements) < 3 or any(b != 2 * a for a, b in pairs):
        raise ValueError(
            f"refinements must double from level to level (at least three), got {refinements!r}"
        )
    if not isinstance(n_modes, int) or n_modes < 1:
        raise ValueError(f"n_modes must be a positive integer, got {n_modes!r}")

    def dense(pm):
        M, C, K, Pc = pm.combine()
        A = first_order(M.toarray(), C.toarray(), K.toarray(), Pc, pm.Fd, np.zeros(pm.n_dofs))[0]
        lam = np.linalg.eigvals(A)
        lam = lam[lam.imag > 1e-9 * np.abs(lam)]
        return lam[np.argsort(lam.imag)][:n_modes]

    out, states = [], []
    previous = None
    for k in refinements:
        pm = parametric_model(params, Mesh().refined(k))
        if k <= _DENSE_UP_TO:
            lam = dense(pm)
        else:  # a coarser level's modes are within a few percent: refine them
            if previous is None:
                previous = dense(parametric_model(params, Mesh().refined(_DENSE_UP_TO)))
            lam = damped_modes(pm, previous)
        if lam.size < n_modes:
            raise ValueError(f"refinement {k}: only {lam.size} oscillatory modes")
        out.append(lam)
        states.append(2 * pm.n_dofs)
        previous = lam
    return ModeStudy(refinements=refinements, states=tuple(states), eigenvalues=np.array(out))


def frequency_responses(
    refinement: int, omega: np.ndarray, params: BeamParameters | None = None
) -> np.ndarray:
    """Voltage-to-tip [m/V] and load-to-tip [m/N] responses of the mesh refined
    ``refinement`` times at ``omega`` [rad/s]: complex array (len(omega), 2)."""
    pm = parametric_model(params, Mesh().refined(int(refinement)))
    M, C, K, Pc = pm.combine()
    F = np.column_stack([Pc, pm.Fd]).astype(complex)
    out = np.empty((len(omega), 2), dtype=complex)
    for i, w in enumerate(np.asarray(omega, dtype=float)):
        out[i] = spla.splu((K + 1j * w * C - w * w * M).tocsc()).solve(F)[pm.tip_index]
    return out


# --- the thesis mesh against the converged plant ----------------------------------
def response_grid(modes: np.ndarray, band: float, points: int = 400) -> np.ndarray:
    """Frequencies [rad/s] for comparing responses up to ``band``: a log grid plus a fine
    grid across each lightly damped resonance (+/- 8 half-power bandwidths)."""
    w = [np.logspace(0.0, np.log10(band), points)]
    for lam in modes:
        half = -lam.real  # half-power half-width of the resonance [rad/s]
        w.append(lam.imag + np.linspace(-8.0, 8.0, 161) * half)
    w = np.unique(np.concatenate(w))
    return w[(w > 0) & (w <= band)]


def converged_responses(
    omega: np.ndarray,
    refinements: tuple[int, int] = (64, 128),
    params: BeamParameters | None = None,
) -> np.ndarray:
    """The mesh-converged model's responses (len(omega), 2), voltage and load to tip:
    pointwise Richardson extrapolation of two refinements (rate 2, module docstring),
    valid where the finer mesh's resonance shift is small against its bandwidth (at
    k = 128 the shift of mode 2 is 0.3 % of it)."""
    coarse, fine = (frequency_responses(k, omega, params) for k in refinements)
    return fine + (fine - coarse) / 3.0


def relative_hinf(g: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """max |g - ref| / max |ref| per column (relative H-infinity error on the grid)."""
    return np.max(np.abs(g - ref), axis=0) / np.max(np.abs(ref), axis=0)
