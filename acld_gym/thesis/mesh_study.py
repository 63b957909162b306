"""The thesis mesh against the mesh-converged plant: the numbers of the documentation's
mesh study, ``docs/mesh.md`` (``acld-gym mesh``), from the mode study of
:mod:`acld_gym.physics.convergence`, the two truth plants, their design models and the
thesis's passive and LQR responses."""

from __future__ import annotations

import numpy as np

from acld_gym.design.pipeline import DESIGN_ORDER, design
from acld_gym.design.reduction import frequency_response, hinf_norm
from acld_gym.design.simulate import simulate
from acld_gym.physics.convergence import (
    converged_responses,
    mode_study,
    relative_hinf,
    response_grid,
)
from acld_gym.physics.loads import Harmonic, TipLoad, thesis_load
from acld_gym.physics.plant import band_of
from acld_gym.physics.truth import plant
from acld_gym.thesis.metrics import peak, settling_time
from acld_gym.thesis.table2 import V_LIMIT

__all__ = ["mesh_report", "format_mesh_report"]


def mesh_report(dt: float = 1e-3) -> dict:
    """The numbers of ``docs/mesh.md`` (``acld-gym mesh``).

    Returns a JSON-able dict: the mode study, both plants' modes against the Richardson
    limits, their responses against the converged model, the design models, and the
    passive and saturated-LQR responses (thesis observer) to the three thesis cases.
    """
    band = band_of(dt)
    study = mode_study()
    limit = study.limit
    zlimit = study.damping_limit
    n_band = int(np.sum(limit < band))
    out: dict = {
        "band_rad_s": band,
        "study": {
            "refinements": list(study.refinements),
            "states": list(study.states),
            "frequencies": study.frequencies.tolist(),
            "damping": study.damping.tolist(),
            "rate": study.rate.tolist(),
            "damping_rate": study.damping_rate.tolist(),
            "limit": limit.tolist(),
            "damping_limit": zlimit.tolist(),
        },
    }
    conv = [lam for lam in study.eigenvalues[-1][:n_band]]
    w = response_grid(np.array(conv), band)
    ref = converged_responses(w)
    plants = {}
    for mesh in ("thesis", "converged"):
        p = plant(mesh, dt)
        lam = p.modes()[: len(limit)]
        A, B, E, C = p.state_space()
        g = np.column_stack([frequency_response(A, B, C, w), frequency_response(A, E, C, w)])
        rec = {
            "states": p.n_states,
            "frequencies": lam.imag.tolist(),
            "damping": (-lam.real / np.abs(lam)).tolist(),
            "frequency_error": (lam.imag / limit - 1).tolist(),
            "damping_error": ((-lam.real / np.abs(lam)) / zlimit - 1).tolist(),
            "hinf_error_voltage": float(relative_hinf(g, ref)[0]),
            "hinf_error_load": float(relative_hinf(g, ref)[1]),
            "designs": {},
            "cases": {},
        }
        for order in sorted({6, DESIGN_ORDER[mesh]}):
            d = design(p, order=order)
            r = d.reduced
            err, _ = hinf_norm(
                np.block(
                    [[A, np.zeros((A.shape[0], order))], [np.zeros((order, A.shape[0])), r.A]]
                ),
                np.vstack([B, r.B]),
                np.hstack([C, -r.C]),
            )
            rec["designs"][order] = {
                "hankel_gap": r.hankel_gap,
                "hinf_error": err,
                "error_bound": r.error_bound,
                "hsv": r.hsv[: order + 2].tolist(),
            }
        d = design(p, order=DESIGN_ORDER[mesh])
        obs = d.observer("thesis")
        for case in (1, 2, 3):
            row = {}
            for name, fb in (("passive", d.passive), ("lqr", d.lqr)):
                res = simulate(A, B, E, C, obs, fb, thesis_load(case), t_end=1.0, v_max=V_LIMIT)
                row[name] = {
                    "peak_mm": 1e3 * peak(res.y),
                    "settling_s": settling_time(res.t, res.y),
                }
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
        res = simulate(A, B, E, C, d.observer("thesis"), d.passive, load, t_end=1.0, v_max=None)
        drive[f"{w0:.2f}"] = 1e3 * peak(res.y)
    out["case3_drive"] = {
        "own_resonance_rad_s": own,
        "passive_peak_mm": drive,
        "phase_drift_rad": (179.0 - own) * 0.193,
    }
    return out


def format_mesh_report(rep: dict) -> str:
    """Markdown tables of :func:`mesh_report`."""
    s = rep["study"]
    n = len(s["limit"])
    lines = [
        "Mode convergence (damped frequencies [rad/s]; error against the Richardson limit)",
        "",
        "| k | states | " + " | ".join(f"mode {j + 1}" for j in range(n)) + " |",
        "|---|---|" + "---|" * n,
    ]
    for k, st, f in zip(s["refinements"], s["states"], s["frequencies"], strict=True):
        cells = [
            f"{x:.2f} ({100 * (x / lim - 1):+.3f} %)" for x, lim in zip(f, s["limit"], strict=True)
        ]
        lines.append(f"| {k} | {st} | " + " | ".join(cells) + " |")
    lines.append("| limit | - | " + " | ".join(f"{x:.2f}" for x in s["limit"]) + " |")
    lines.append(
        "| fitted rate (frequency) | - | " + " | ".join(f"{x:.2f}" for x in s["rate"]) + " |"
    )
    lines.append(
        "| damping ratio limit | - | " + " | ".join(f"{x:.5f}" for x in s["damping_limit"]) + " |"
    )
    lines.append(
        "| fitted rate (damping) | - | " + " | ".join(f"{x:.2f}" for x in s["damping_rate"]) + " |"
    )
    lines += [
        "",
        f"Plants against the converged model (modes; responses up to "
        f"{rep['band_rad_s']:.0f} rad/s, relative H-infinity error)",
        "",
        "| plant | states | "
        + " | ".join(f"mode {j + 1}: f, zeta" for j in range(n))
        + " | V -> tip | load -> tip |",
        "|---|---|" + "---|" * (n + 2),
    ]
    for mesh, r in rep["plants"].items():
        cells = [
            f"{100 * ef:+.3f} %, {100 * ez:+.2f} %"
            for ef, ez in zip(r["frequency_error"], r["damping_error"], strict=True)
        ]
        lines.append(
            f"| {mesh} | {r['states']} | "
            + " | ".join(cells)
            + f" | {100 * r['hinf_error_voltage']:.2f} % | "
            f"{100 * r['hinf_error_load']:.2f} % |"
        )
    lines += [
        "",
        "Design models (balanced truncation of each plant, voltage to tip)",
        "",
        "| plant | order | sigma_k / sigma_k+1 | H-inf error | bound 2 sum sigma_i |",
        "|---|---|---|---|---|",
    ]
    for mesh, r in rep["plants"].items():
        for order, dsg in r["designs"].items():
            lines.append(
                f"| {mesh} | {order} | {dsg['hankel_gap']:.2f} | "
                f"{dsg['hinf_error']:.3e} | {dsg['error_bound']:.3e} |"
            )
    lines += [
        "",
        "Passive and saturated LQR, thesis observer (exact simulation, 1 s)",
        "",
        "| case | passive peak [mm] thesis -> converged | LQR peak [mm] | LQR settling [s] |",
        "|---|---|---|---|",
    ]
    t, c = rep["plants"]["thesis"]["cases"], rep["plants"]["converged"]["cases"]
    for case in t:
        lines.append(
            f"| {case} | {t[case]['passive']['peak_mm']:.3f} -> "
            f"{c[case]['passive']['peak_mm']:.3f} | {t[case]['lqr']['peak_mm']:.3f} -> "
            f"{c[case]['lqr']['peak_mm']:.3f} | {t[case]['lqr']['settling_s']:.3f} -> "
            f"{c[case]['lqr']['settling_s']:.3f} |"
        )
    dr = rep["case3_drive"]
    peaks = ", ".join(f"{k} rad/s: {v:.3f} mm" for k, v in dr["passive_peak_mm"].items())
    lines += [
        "",
        f"Load case 3 on the converged plant (its resonance "
        f"{dr['own_resonance_rad_s']:.2f} rad/s): passive peak at {peaks}; phase "
        f"drift of the 179 rad/s drive over 0.193 s: {dr['phase_drift_rad']:.2f} rad.",
    ]
    return "\n".join(lines)
