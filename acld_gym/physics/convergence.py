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

__all__ = ["ModeStudy", "mode_study", "frequency_responses", "richardson", "REFINEMENTS"]

#: Refinement factors of the default study (the finest is the converged plant's mesh).
REFINEMENTS = (1, 2, 4, 8, 16, 32, 64, 128)
_DENSE_UP_TO = 8  # dense eigenvalues up to this refinement, sparse inverse iteration beyond


def richardson(coarse: np.ndarray, mid: np.ndarray,
               fine: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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
            cells = [f"{fj:.2f} ({100 * (fj / lj - 1):+.3f} %)" for fj, lj in zip(f, self.limit,
                                                                                   strict=True)]
            rows.append(f"| {k} | {s} | " + " | ".join(cells) + " |")
        rows.append("| limit (Richardson) | - | " + " | ".join(f"{x:.2f}" for x in self.limit)
                    + " |")
        rows.append("| fitted rate p | - | " + " | ".join(f"{x:.2f}" for x in self.rate) + " |")
        return "\n".join(rows)


def mode_study(n_modes: int = 4, refinements: tuple[int, ...] = REFINEMENTS,
               params: BeamParameters | None = None) -> ModeStudy:
    """The first ``n_modes`` damped modes on each refinement (a doubling sequence)."""
    refinements = tuple(int(k) for k in refinements)
    pairs = zip(refinements[:-1], refinements[1:], strict=True)
    if len(refinements) < 3 or any(b != 2 * a for a, b in pairs):
        raise ValueError(f"refinements must double from level to level (at least three), got "
                         f"{refinements!r}")
    if not isinstance(n_modes, int) or n_modes < 1:
        raise ValueError(f"n_modes must be a positive integer, got {n_modes!r}")
    def dense(pm):
        M, C, K, Pc = pm.combine()
        A = first_order(M.toarray(), C.toarray(), K.toarray(), Pc, pm.Fd,
                        np.zeros(pm.n_dofs))[0]
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


def frequency_responses(refinement: int, omega: np.ndarray,
                        params: BeamParameters | None = None) -> np.ndarray:
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


def converged_responses(omega: np.ndarray, refinements: tuple[int, int] = (64, 128),
                        params: BeamParameters | None = None) -> np.ndarray:
    """The mesh-converged model's responses (len(omega), 2), voltage and load to tip:
    pointwise Richardson extrapolation of two refinements (rate 2, module docstring),
    valid where the finer mesh's resonance shift is small against its bandwidth (at
    k = 128 the shift of mode 2 is 0.3 % of it)."""
    coarse, fine = (frequency_responses(k, omega, params) for k in refinements)
    return fine + (fine - coarse) / 3.0


def relative_hinf(g: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """max |g - ref| / max |ref| per column (relative H-infinity error on the grid)."""
    return np.max(np.abs(g - ref), axis=0) / np.max(np.abs(ref), axis=0)


def mesh_report(dt: float = 1e-3) -> dict:
    """The README's "Thesis mesh vs converged plant" numbers (``acld-gym mesh``).

    Returns a JSON-able dict: the mode study, both plants' modes against the Richardson
    limits, their responses against the converged model, the design models, and the
    passive and saturated-LQR responses (thesis observer) to the three thesis cases.
    """
    from acld_gym.design.pipeline import DESIGN_ORDER, design
    from acld_gym.design.reduction import frequency_response, hinf_norm
    from acld_gym.design.simulate import simulate
    from acld_gym.physics.loads import Harmonic, TipLoad, thesis_load
    from acld_gym.physics.plant import band_of
    from acld_gym.physics.truth import plant
    from acld_gym.thesis.metrics import peak, settling_time
    from acld_gym.thesis.table2 import V_LIMIT

    band = band_of(dt)
    study = mode_study()
    limit = study.limit
    zlimit = study.damping_limit
    n_band = int(np.sum(limit < band))
    out: dict = {"band_rad_s": band, "study": {
        "refinements": list(study.refinements), "states": list(study.states),
        "frequencies": study.frequencies.tolist(), "damping": study.damping.tolist(),
        "rate": study.rate.tolist(), "damping_rate": study.damping_rate.tolist(),
        "limit": limit.tolist(), "damping_limit": zlimit.tolist()}}
    conv = [lam for lam in study.eigenvalues[-1][:n_band]]
    w = response_grid(np.array(conv), band)
    ref = converged_responses(w)
    plants = {}
    for mesh in ("thesis", "converged"):
        p = plant(mesh, dt)
        lam = p.modes()[:len(limit)]
        A, B, E, C = p.state_space()
        g = np.column_stack([frequency_response(A, B, C, w), frequency_response(A, E, C, w)])
        rec = {"states": p.n_states, "frequencies": lam.imag.tolist(),
               "damping": (-lam.real / np.abs(lam)).tolist(),
               "frequency_error": (lam.imag / limit - 1).tolist(),
               "damping_error": ((-lam.real / np.abs(lam)) / zlimit - 1).tolist(),
               "hinf_error_voltage": float(relative_hinf(g, ref)[0]),
               "hinf_error_load": float(relative_hinf(g, ref)[1]), "designs": {}, "cases": {}}
        for order in sorted({6, DESIGN_ORDER[mesh]}):
            d = design(p, order=order)
            r = d.reduced
            err, _ = hinf_norm(np.block([[A, np.zeros((A.shape[0], order))],
                                         [np.zeros((order, A.shape[0])), r.A]]),
                               np.vstack([B, r.B]), np.hstack([C, -r.C]))
            rec["designs"][order] = {"hankel_gap": r.hankel_gap, "hinf_error": err,
                                     "error_bound": r.error_bound,
                                     "hsv": r.hsv[:order + 2].tolist()}
        d = design(p, order=DESIGN_ORDER[mesh])
        obs = d.observer("thesis")
        for case in (1, 2, 3):
            row = {}
            for name, fb in (("passive", d.passive), ("lqr", d.lqr)):
                res = simulate(A, B, E, C, obs, fb, thesis_load(case), t_end=1.0,
                               v_max=V_LIMIT)
                row[name] = {"peak_mm": 1e3 * peak(res.y),
                             "settling_s": settling_time(res.t, res.y)}
            rec["cases"][case] = row
        plants[mesh] = rec
    out["plants"] = plants
    # Load case 3 at 179 rad/s (the thesis's) or at the converged plant's own resonance.
    p = plant("converged", dt)
    A, B, E, C = p.state_space()
    d = design(p, order=DESIGN_ORDER["converged"])
    own = float(p.modes()[0].imag)
    drive = {}
    for w0 in (179.0, own):
        load = TipLoad((Harmonic(0.1, w0, 0.0, 0.193),))
        res = simulate(A, B, E, C, d.observer("thesis"), d.passive, load, t_end=1.0,
                       v_max=None)
        drive[f"{w0:.2f}"] = 1e3 * peak(res.y)
    out["case3_drive"] = {"own_resonance_rad_s": own, "passive_peak_mm": drive,
                          "phase_drift_rad": (179.0 - own) * 0.193}
    return out


def format_mesh_report(rep: dict) -> str:
    """Markdown tables of :func:`mesh_report`."""
    s = rep["study"]
    n = len(s["limit"])
    lines = ["Mode convergence (damped frequencies [rad/s]; error against the Richardson limit)",
             "", "| k | states | " + " | ".join(f"mode {j + 1}" for j in range(n)) + " |",
             "|---|---|" + "---|" * n]
    for k, st, f in zip(s["refinements"], s["states"], s["frequencies"], strict=True):
        cells = [f"{x:.2f} ({100 * (x / lim - 1):+.3f} %)" for x, lim in zip(f, s["limit"],
                                                                          strict=True)]
        lines.append(f"| {k} | {st} | " + " | ".join(cells) + " |")
    lines.append("| limit | - | " + " | ".join(f"{x:.2f}" for x in s["limit"]) + " |")
    lines.append("| fitted rate (frequency) | - | "
                 + " | ".join(f"{x:.2f}" for x in s["rate"]) + " |")
    lines.append("| damping ratio limit | - | "
                 + " | ".join(f"{x:.5f}" for x in s["damping_limit"]) + " |")
    lines.append("| fitted rate (damping) | - | "
                 + " | ".join(f"{x:.2f}" for x in s["damping_rate"]) + " |")
    lines += ["", f"Plants against the converged model (modes; responses up to "
              f"{rep['band_rad_s']:.0f} rad/s, relative H-infinity error)", "",
              "| plant | states | " + " | ".join(f"mode {j + 1}: f, zeta" for j in range(n))
              + " | V -> tip | load -> tip |", "|---|---|" + "---|" * (n + 2)]
    for mesh, r in rep["plants"].items():
        cells = [f"{100 * ef:+.3f} %, {100 * ez:+.2f} %" for ef, ez in
                 zip(r["frequency_error"], r["damping_error"], strict=True)]
        lines.append(f"| {mesh} | {r['states']} | " + " | ".join(cells)
                     + f" | {100 * r['hinf_error_voltage']:.2f} % | "
                       f"{100 * r['hinf_error_load']:.2f} % |")
    lines += ["", "Design models (balanced truncation of each plant, voltage to tip)", "",
              "| plant | order | sigma_k / sigma_k+1 | H-inf error | bound 2 sum sigma_i |",
              "|---|---|---|---|---|"]
    for mesh, r in rep["plants"].items():
        for order, dsg in r["designs"].items():
            lines.append(f"| {mesh} | {order} | {dsg['hankel_gap']:.2f} | "
                         f"{dsg['hinf_error']:.3e} | {dsg['error_bound']:.3e} |")
    lines += ["", "Passive and saturated LQR, thesis observer (exact simulation, 1 s)", "",
              "| case | passive peak [mm] thesis -> converged | LQR peak [mm] | "
              "LQR settling [s] |", "|---|---|---|---|"]
    t, c = rep["plants"]["thesis"]["cases"], rep["plants"]["converged"]["cases"]
    for case in t:
        lines.append(f"| {case} | {t[case]['passive']['peak_mm']:.3f} -> "
                     f"{c[case]['passive']['peak_mm']:.3f} | {t[case]['lqr']['peak_mm']:.3f} -> "
                     f"{c[case]['lqr']['peak_mm']:.3f} | {t[case]['lqr']['settling_s']:.3f} -> "
                     f"{c[case]['lqr']['settling_s']:.3f} |")
    dr = rep["case3_drive"]
    peaks = ", ".join(f"{k} rad/s: {v:.3f} mm" for k, v in dr["passive_peak_mm"].items())
    lines += ["", f"Load case 3 on the converged plant (its resonance "
              f"{dr['own_resonance_rad_s']:.2f} rad/s): passive peak at {peaks}; phase "
              f"drift of the 179 rad/s drive over 0.193 s: {dr['phase_drift_rad']:.2f} rad."]
    return "\n".join(lines)
