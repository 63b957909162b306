"""An :class:`~baselines.analysis.control.Analysis` for people: the text summary
``python -m baselines.analyze`` prints, the Bode magnitude figure, and the markdown
comparison of several policies."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from acld_gym.util.atomic import save_figure
from baselines.evaluation.score import SCORE_NAME

from .control import Analysis

__all__ = ["format_analysis", "plot_compliance", "markdown_summary"]


def _mode(m) -> str:
    if m is None:
        return "-"
    return f"{m.frequency_rad_s:8.2f} rad/s, zeta {m.damping_ratio:.5f}"


def _num(x, fmt: str, scale: float = 1.0) -> str:
    return "-" if x is None or not np.isfinite(x) else format(x * scale, fmt)


def format_analysis(a: Analysis) -> str:
    """The summary: modes, peak reductions, margins, effort per case, the score."""
    out = [f"{a.policy} on {a.env_id}"]
    modal, comp = a.modal, a.compliance
    red = comp.peak_reduction_db if comp.valid else None
    out.append(
        f"\nclosed-loop modes (modal test: {modal.reason}"
        + (
            f"; pulse {modal.pulse_N:.3g} N, max |V| {modal.max_voltage_V:.3g} V, "
            f"ERA order {modal.identification.order}"
            if modal.identification is not None
            else ""
        )
        + ")"
    )
    out.append(
        f"{'mode':>4}  {'passive':>30}  {'closed loop, identified':>30}  "
        f"{'closed loop, exact':>30}  {'peak drop':>9}"
    )
    for i, p in enumerate(a.open_loop_modes):
        ex = a.exact_modes[i] if a.exact_modes is not None else None
        drop = "-" if red is None else f"{red[i]:6.2f} dB"
        out.append(
            f"{i + 1:>4}  {_mode(p):>30}  {_mode(modal.modes[i]):>30}  {_mode(ex):>30}  {drop:>9}"
        )
    if not comp.valid:
        out.append(f"compliance test: {comp.reason}")
    out.append(f"\nsmall-signal law: {a.law_reason}")
    if a.margins is not None:
        m = a.margins
        out.append(
            f"margins at the actuator: gain {_num(m['gain_margin_db'], '.2f')} dB "
            f"(at {_num(m['gain_margin_rad_s'], '.1f')} rad/s; reduction "
            f"{_num(m['gain_reduction_margin_db'], '.2f')} dB), phase "
            f"{_num(m['phase_margin_deg'], '.1f')} deg "
            f"(at {_num(m['phase_margin_rad_s'], '.1f')} rad/s); closed loop "
            f"{'stable' if m['closed_loop_stable'] else 'UNSTABLE'} (spectral radius "
            f"{m['closed_loop_spectral_radius']:.5f})"
        )
    out.append(
        f"\n{'case':>4} {'ISE [m^2 s]':>12} {'V rms [V]':>10} {'Q [mvar]':>9} "
        f"{'settled from [s]':>16} {'TV [kV/s]':>10} {'at limit':>9} {'tip rms [um]':>12}"
    )
    for case, r in a.cases.items():
        out.append(
            f"{case:>4} {r['ise']:12.4e} {r['rms_voltage_V']:10.1f} "
            f"{_num(r['reactive_power_var'], '9.2f', 1e3)} {r['settled_from_s']:16.3f} "
            f"{_num(r['total_variation_V_per_s'], '10.2f', 1e-3)} "
            f"{_num(r['limit_fraction'], '8.1%')} "
            f"{_num(r['residual_tip_rms_m'], '12.2f', 1e6)}"
        )
    if a.score is not None:
        s = a.score
        rel = s.ise_rel_thesis_lqr
        out.append(
            f"\n{SCORE_NAME} on {s.test_set} ({s.n_episodes} episodes; passive 0, "
            f"clairvoyant bound 1): IQM {s.iqm:.4f} [95 % CI {s.ci_low:.4f}, {s.ci_high:.4f}]"
            f"; mean ISE / thesis LQR {rel:.4f}"
        )
    return "\n".join(out)


def plot_compliance(a: Analysis, path: str | Path) -> Path:
    """Bode magnitude of the load-to-tip compliance, passive against the closed loop
    (measured; the exact loop dashed for a linear policy), with the identified modes
    marked."""
    import matplotlib  # ~0.3 s to import (with pyplot): only the figure needs it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # (the same)

    comp = a.compliance
    w = comp.omega
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.semilogx(
        w, 20 * np.log10(np.abs(comp.passive)), color="0.55", lw=0.8, label="passive (measured)"
    )
    if comp.closed is not None:
        ax.semilogx(
            w,
            20 * np.log10(np.abs(comp.closed)),
            color="C0",
            lw=0.8,
            label=f"{a.policy} (measured)",
        )
    if a.exact_compliance is not None:
        ax.semilogx(
            w,
            20 * np.log10(np.abs(a.exact_compliance)),
            color="C1",
            lw=0.8,
            ls="--",
            label=f"{a.policy} (exact loop)",
        )
    ylo, yhi = ax.get_ylim()
    for m in a.open_loop_modes:
        if m is not None:
            ax.axvline(m.frequency_rad_s, color="0.7", lw=0.6, ls=":")
    for i, m in enumerate(a.modal.modes):
        if m is None:
            continue
        ax.axvline(m.frequency_rad_s, color="C3", lw=0.7, ls="--")
        ax.annotate(
            f"mode {i + 1}\n{m.frequency_rad_s:.0f} rad/s\n$\\zeta$ = {m.damping_ratio:.4f}",
            (m.frequency_rad_s, yhi),
            xytext=(3, -4),
            textcoords="offset points",
            va="top",
            fontsize=7,
            color="C3",
        )
    ax.set_xlim(w[0], w[-1])
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel("tip / load [dB re 1 m/N]")
    ax.set_title(
        f"{a.env_id}: load-to-tip compliance, passive and {a.policy} "
        "(identified closed-loop modes marked)",
        fontsize=9,
    )
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    out = save_figure(fig, path, dpi=110)
    plt.close(fig)
    return out


def _cell(m, exact=None) -> str:
    if m is None:
        return (
            "-"
            if exact is None
            else (f"- [exact {exact.frequency_rad_s:.1f}, {exact.damping_ratio:.4f}]")
        )
    text = f"{m.frequency_rad_s:.1f}, {m.damping_ratio:.4f}"
    return text if exact is None else f"{text} [{exact.damping_ratio:.4f}]"


def _stable(a: Analysis) -> bool:
    return a.margins is None or a.margins["closed_loop_stable"]


def _loop(a: Analysis) -> str:
    """One phrase on the policy's small-signal loop."""
    parts = []
    if a.law is None:
        parts.append("not linear about rest")
    elif a.margins is None:
        parts.append("linear, no feedback")
    else:
        rho = a.margins["closed_loop_spectral_radius"]
        parts.append(f"linear, {'stable' if rho < 1 else 'UNSTABLE'} (spectral radius {rho:.4f})")
    if not a.modal.rests:
        parts.append(
            "at the limit without load" if "limit" in a.modal.reason else "no rest without load"
        )
    return "; ".join(parts)


def markdown_summary(results: list[Analysis]) -> str:
    """The comparison of several analyses as markdown: the modes, the peaks, margins and
    score, and the effort on thesis case 1."""
    out = [
        "Closed-loop modes 1-3, identified through the env: frequency [rad/s], damping "
        "ratio [exact closed-loop eigenvalue's damping ratio, for a policy linear about "
        "rest]; the passive row is the open-loop beam.",
        "",
        "| policy | mode 1 | mode 2 | mode 3 | small-signal loop |",
        "|---|---|---|---|---|",
    ]
    if results:
        out.append(
            "| (open loop) | " + " | ".join(_cell(m) for m in results[0].open_loop_modes) + " | - |"
        )
    for a in results:
        exact = a.exact_modes or [None] * len(a.modal.modes)
        out.append(
            f"| {a.policy} | "
            + " | ".join(_cell(m, e) for m, e in zip(a.modal.modes, exact, strict=True))
            + f" | {_loop(a)} |"
        )
    out += [
        "",
        "Peak reduction of the load-to-tip compliance against the passive beam "
        "(multisine through the env), margins of the loop broken at the actuator, and the "
        f"{SCORE_NAME} (IQM [95 % CI] of (ISE_passive - ISE) / (ISE_passive - ISE_bound) on "
        "the test set: passive 0, clairvoyant bound 1) and, thesis-facing, the mean ISE "
        "relative to the thesis LQR's.",
        "",
        "| policy | peak drop mode 1 / 2 / 3 [dB] | gain margin [dB] | phase margin [deg] "
        f"| {SCORE_NAME} | 95 % CI | episodes | ISE / thesis LQR |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for a in results:
        red = a.compliance.peak_reduction_db if a.compliance.valid else None
        drops = "-" if red is None else " / ".join(f"{d:.1f}" for d in red)
        m = a.margins or {}
        gm = _num(m.get("gain_margin_db"), ".1f") if _stable(a) else "unstable"
        pm = _num(m.get("phase_margin_deg"), ".1f") if _stable(a) else "unstable"
        s = a.score
        score = (
            ("-", "-", "-", "-")
            if s is None
            else (
                f"{s.iqm:.3f}",
                f"[{s.ci_low:.3f}, {s.ci_high:.3f}]",
                str(s.n_episodes),
                _num(s.ise_rel_thesis_lqr, ".3f"),
            )
        )
        out.append(f"| {a.policy} | {drops} | {gm} | {pm} | " + " | ".join(score) + " |")
    out += [
        "",
        "Effort on thesis case 1 (seed 0): over the episode, and after the tip has "
        "settled (from 0.5 s after the load).",
        "",
        "| policy | V rms [V] | reactive power [mvar] | V rms settled [V] "
        "| TV settled [kV/s] | at limit settled | tip rms settled [um] |",
        "|---|---|---|---|---|---|---|",
    ]
    for a in results:
        r = a.cases[1]
        out.append(
            f"| {a.policy} | {r['rms_voltage_V']:.1f} "
            f"| {_num(r['reactive_power_var'], '.1f', 1e3)} "
            f"| {_num(r['settled_rms_voltage_V'], '.1f')} "
            f"| {_num(r['total_variation_V_per_s'], '.1f', 1e-3)} "
            f"| {_num(r['limit_fraction'], '.0%')} "
            f"| {_num(r['residual_tip_rms_m'], '.1f', 1e6)} |"
        )
    return "\n".join(out)
