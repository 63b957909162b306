r"""Every lightly damped mode of a sparse (fine-mesh) model below a frequency.

The converged plant interpolates the fine mesh at each resonance below its band
(:mod:`acld_gym.physics.krylov`), so it needs all of them, each once. Starting guesses
from a coarser mesh cannot provide that: a coarse mesh lacks some of the fine mesh's
modes altogether (the 4x mesh has none near 18 100 rad/s, where the 128x mesh has one)
and places others 10-20 % too high, nearer a neighbour than their own mode.

:func:`modes_below` therefore enumerates the fine model's spectrum directly, by
shift-invert Arnoldi (ARPACK) on the linearized pencil

.. math::

    \begin{bmatrix}0 & I\\ -K & -C\end{bmatrix} z = \lambda
    \begin{bmatrix}I & 0\\ 0 & M\end{bmatrix} z

at centres :math:`j w` on the imaginary axis. The ``k`` eigenvalues returned at a centre
are its ``k`` nearest, so every eigenvalue strictly inside the disk through the farthest
of them is among them. The first centre is the middle of the range, each next one the
middle of a part not yet covered, until the disks together cover the sector
:math:`\{\lambda : 0 \le \operatorname{Im}\lambda \le w_{max},\ \zeta(\lambda) \le
\zeta_{max}\}`: at height y the segment from :math:`-t y` to 0 (with
:math:`t = \zeta_{max} / \sqrt{1 - \zeta_{max}^2}`) lies in the disk of centre
:math:`j w` and radius r when :math:`(t y)^2 + (y - w)^2 \le r^2`.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from acld_gym.physics.model import ParametricModel

__all__ = ["modes_below", "damped_modes", "ZETA_MAX", "pencil"]

#: Damping ratio above which a mode is no resonance to interpolate at (its peak gain
#: over the static one is below about 1 / (2 zeta) = 1.7). The beam's modes below
#: 9e4 rad/s have zeta <= 0.053 on the 128x mesh.
ZETA_MAX = 0.3

#: Eigenvalues per shift-invert Arnoldi run (doubled, up to ``_K_MAX``, where the disk
#: they fill is too small for the sector).
_K = 16
_K_MAX = 256

#: Most Arnoldi runs of one call (the beam needs 2 or 3 up to 8e4 rad/s).
_RUNS_MAX = 100

#: Relative distance below which two refined eigenvalues are the same one.
_SAME = 1e-9


def pencil(pm: ParametricModel) -> tuple[sp.csc_matrix, sp.csc_matrix]:
    """The linearized pencil ``(A, B)`` of ``pm`` (complex sparse, module docstring)."""
    M, C, K, _ = pm.combine()
    eye = sp.identity(pm.n_dofs, format="csc")
    A = sp.bmat([[None, eye], [-K, -C]], format="csc").astype(complex)
    B = sp.bmat([[eye, None], [None, M]], format="csc").astype(complex)
    return A, B


def damped_modes(
    pm: ParametricModel, guesses: np.ndarray, iterations: int = 3, inner: int = 4
) -> np.ndarray:
    r"""The damped eigenvalues of the (sparse) model nearest to ``guesses`` [1/s].

    Inverse iteration on the linearized pencil
    :math:`\begin{bmatrix}0 & I\\ -K & -C\end{bmatrix} z = \lambda
    \begin{bmatrix}I & 0\\ 0 & M\end{bmatrix} z`, with the shift moved to the
    current estimate ``iterations`` times (``inner`` solves each): from guesses much
    nearer their mode than any other mode (within a few percent for the low modes of a
    coarser mesh) this converges to round-off. A guess nearer another mode converges to that one.
    Returns the eigenvalues with Im > 0.
    """
    A, B = pencil(pm)
    n = pm.n_dofs
    out = []
    for g in guesses:
        sigma = complex(g)
        z = np.ones(2 * n, dtype=complex)  # deterministic start
        for _ in range(iterations):
            lu = spla.splu((A - sigma * B).tocsc())
            for _ in range(inner):
                y = lu.solve(B @ z)
                nu = np.vdot(z, y) / np.vdot(z, z)
                z = y / np.linalg.norm(y)
            sigma = sigma + 1.0 / nu
        out.append(complex(sigma.real, abs(sigma.imag)))
    return np.array(out)


def _nearest(A, B, w: float, k: int) -> tuple[np.ndarray, float]:
    """The ``k`` eigenvalues nearest to ``j w`` and the radius of the disk they fill."""
    lu = spla.splu((A - 1j * w * B).tocsc())
    op = spla.LinearOperator(A.shape, matvec=lambda v: lu.solve(B @ v), dtype=complex)
    v0 = np.random.default_rng(0).standard_normal(A.shape[0]).astype(complex)  # fixed start
    mu = spla.eigs(op, k=k, which="LM", v0=v0, ncv=max(4 * k, 64), tol=1e-10)[0]
    lam = 1j * w + 1.0 / mu
    return lam, float(np.max(np.abs(lam - 1j * w)))


def _covered(w: float, r: float, t: float) -> tuple[float, float]:
    """Heights y whose sector segment [-t y, 0] lies in the disk (j w, r) (module
    docstring); an empty interval as (inf, -inf)."""
    disc = r * r * (1 + t * t) - (t * w) ** 2
    if disc <= 0:
        return np.inf, -np.inf
    root = np.sqrt(disc)
    return (w - root) / (1 + t * t), (w + root) / (1 + t * t)


def modes_below(
    pm: ParametricModel, w_max: float, zeta_max: float = ZETA_MAX, k: int = _K
) -> np.ndarray:
    """Every eigenvalue :math:`\\sigma + j\\omega` of ``pm`` with
    :math:`0 < \\omega < w_{max}` and damping ratio at most ``zeta_max``, ascending in
    :math:`\\omega` (module docstring), each once (eigenvalues closer than 1e-9 relative
    are one), to round-off: Arnoldi's eigenvalues far from their centre are only accurate
    to ~1e-4 (the pencil is far from normal), so each is refined by
    :func:`damped_modes` before copies are merged.
    """
    A, B = pencil(pm)
    t = zeta_max / np.sqrt(1.0 - zeta_max**2)
    found: list[complex] = []
    todo = [(0.0, float(w_max))]  # heights whose sector segments are not yet covered
    for _ in range(_RUNS_MAX):
        if not todo:
            return _distinct(damped_modes(pm, np.array(found)), w_max, zeta_max)
        a, b = todo.pop()
        w = 0.5 * (a + b)
        lam, r = _nearest(A, B, w, k)
        lo, hi = _covered(w, 0.999 * r, t)
        if not lo <= w <= hi:  # the disk misses the sector here: ask for more eigenvalues
            k = min(2 * k, _K_MAX)
            todo.append((a, b))
            continue
        found += [z for z in lam if abs(z - 1j * w) < 0.999 * r and _near_sector(z, w_max, t)]
        todo += [(x, y) for x, y in ((a, lo), (hi, b)) if x < y]
    raise np.linalg.LinAlgError(
        f"modes_below: {_RUNS_MAX} Arnoldi runs did not cover the modes below {w_max:.6g} rad/s"
    )


def _near_sector(z: complex, w_max: float, t: float) -> bool:
    """Whether ``z`` may be in the sector once refined (1 % margins)."""
    return 0.0 < z.imag < 1.01 * w_max and -z.real <= 1.01 * t * z.imag


def _distinct(lam: np.ndarray, w_max: float, zeta_max: float) -> np.ndarray:
    """The refined eigenvalues in the sector, each once (the copies found from several
    centres converge to the same one; eigenvalues closer than :data:`_SAME` relative are
    one), ascending in frequency."""
    lam = lam[(lam.imag > 1e-9 * np.abs(lam)) & (lam.imag < w_max)]
    lam = lam[-lam.real <= zeta_max * np.abs(lam)]
    keep: list[complex] = []
    for z in lam[np.argsort(lam.imag)]:
        if all(abs(z - y) > _SAME * abs(z) for y in keep):
            keep.append(z)
    return np.array(keep)
