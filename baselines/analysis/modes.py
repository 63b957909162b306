r"""Modes of a sampled system seen at the tip: poles, residues, and which pole is "mode i".

A sampled single-input, single-output system with distinct poles :math:`z_j` has the
pulse response :math:`h_k = \sum_j r_j z_j^{k-1}` (k >= 1), with residues
:math:`r_j = (C v_j)(w_j B)` (:math:`v_j, w_j` the right and left eigenvectors, scaled so
that :math:`w_j v_j = 1`; a residue does not depend on how the eigenvectors are scaled
or signed). Each pole is a continuous-time mode :math:`s_j = \ln z_j / \Delta` with
frequency :math:`\omega_j = |s_j|` and damping ratio :math:`\zeta_j = -\Re s_j / |s_j|`.

A closed loop has more poles than the beam has modes (observer, feedback, aliases of the
modes above the Nyquist frequency), so "closed-loop mode i" needs a rule. The same one is
applied to identified and to exact poles (:func:`select_modes`): mode i is the oscillatory
pole pair with the largest energy in the tip's pulse response over the observed window,
:math:`\sum_{k<N} |r_j|^2 |z_j|^{2k}`, among those whose frequency lies in band i and
whose damping ratio is below :data:`MAX_DAMPING` (a more damped pole, such as an
observer's or a feedback's real-like pair, decays within a few periods: it is no
vibration mode, and ERA need not resolve it). The
bands split the frequency axis at the geometric means of the open-loop modes' frequencies
(:func:`band_edges`), up to the Nyquist frequency.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "Mode",
    "poles_and_residues",
    "band_edges",
    "select_modes",
    "window_energy",
    "MAX_DAMPING",
]

#: Largest damping ratio of a pole that counts as a mode.
MAX_DAMPING = 0.5


@dataclass(frozen=True)
class Mode:
    """One mode: a sampled pole pair and its continuous-time reading."""

    frequency_rad_s: float
    """Natural frequency :math:`|s|` [rad/s]."""
    damping_ratio: float
    """:math:`-\\Re s / |s|` [-] (negative: an unstable mode)."""
    pole: complex
    """The sampled pole z (upper half plane)."""
    energy: float
    """Its energy in the tip's pulse response over the window [(m/N)^2, or the data's
    unit squared]."""

    @classmethod
    def of_pole(cls, z: complex, dt: float, energy: float = float("nan")) -> Mode:
        s = np.log(complex(z)) / dt
        return cls(
            frequency_rad_s=float(abs(s)),
            damping_ratio=float(-s.real / abs(s)),
            pole=complex(z),
            energy=float(energy),
        )

    def as_dict(self) -> dict:
        """``{"frequency_rad_s", "damping_ratio"}`` (the JSON form)."""
        return {"frequency_rad_s": self.frequency_rad_s, "damping_ratio": self.damping_ratio}


def poles_and_residues(
    A: np.ndarray, B: np.ndarray, C: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Poles z (n,) and residues r (n,) of :math:`C (zI - A)^{-1} B` (single input and
    output; distinct poles)."""
    z, V = np.linalg.eig(np.asarray(A, dtype=float))
    W = np.linalg.solve(V, np.eye(V.shape[0]))
    r = (np.asarray(C, dtype=float).reshape(1, -1) @ V)[0] * (W @ np.asarray(B, float).ravel())
    return z, r


def window_energy(z: np.ndarray, r: np.ndarray, n: int) -> np.ndarray:
    r""":math:`\sum_{k<n} |r|^2 |z|^{2k}`, the energy of each modal term over n samples
    (finite for unstable poles too)."""
    q = np.abs(z) ** 2
    with np.errstate(over="ignore", invalid="ignore"):
        geo = np.where(np.isclose(q, 1.0, rtol=0, atol=1e-14), float(n), (1.0 - q**n) / (1.0 - q))
    return np.abs(r) ** 2 * geo


def band_edges(frequencies, dt: float) -> np.ndarray:
    """Edges [rad/s] of the bands around the open-loop modes ``frequencies`` (ascending):
    0, the geometric means of neighbours, and the Nyquist frequency pi / dt last."""
    w = np.sort(np.asarray(frequencies, dtype=float))
    if w.size < 1 or not np.all(w > 0):
        raise ValueError(f"frequencies must be positive [rad/s], got {frequencies!r}")
    nyquist = np.pi / dt
    inner = np.sqrt(w[:-1] * w[1:])
    return np.concatenate([[0.0], inner, [nyquist]])


def select_modes(
    z: np.ndarray, r: np.ndarray, dt: float, edges: np.ndarray, n_window: int
) -> list[Mode | None]:
    """Mode i: the oscillatory pole (Im z > 0, damping ratio below :data:`MAX_DAMPING`) with
    frequency in [edges[i], edges[i+1])
    (the last band open above: a heavily damped pole's :math:`|s|` can exceed the Nyquist
    frequency) of largest :func:`window_energy`; None for a band without one."""
    z = np.asarray(z, dtype=complex)
    e = window_energy(z, r, n_window)
    osc = z.imag > 1e-9 * np.maximum(np.abs(z), 1.0)
    s = np.log(np.where(osc, z, 1.0)) / dt
    w = np.abs(s)
    osc &= -s.real < MAX_DAMPING * np.maximum(w, 1e-300)
    out: list[Mode | None] = []
    tops = np.append(np.asarray(edges[1:-1], dtype=float), np.inf)
    for lo, hi in zip(edges[:-1], tops, strict=True):
        cand = np.flatnonzero(osc & (w >= lo) & (w < hi))
        if cand.size == 0:
            out.append(None)
            continue
        j = cand[np.argmax(e[cand])]
        out.append(Mode.of_pole(z[j], dt, e[j]))
    return out
