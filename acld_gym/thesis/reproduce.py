"""The thesis's chapter-5 study: three load cases x {passive, LQR, SMC} x {saturated, not}.

Uses the thesis's observer fed the tip load (see :mod:`acld_gym.design.observer`)
and simulates the full 38-state plant with :mod:`acld_gym.design.simulate`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from acld_gym.design.pipeline import Design
from acld_gym.design.simulate import SimulationResult, simulate
from acld_gym.physics.loads import THESIS_CASES, thesis_load
from acld_gym.thesis.metrics import max_abs, peak, settling_time
from acld_gym.thesis.table2 import PASSIVE_CASE1_PEAK_MM, V_LIMIT, Table2Row, thesis_row

__all__ = ["Table2Row", "run_cases", "format_table2", "T_END"]

#: Simulated window [s]; the thesis's settling times all lie below 1 s and
#: do not change with a longer window.
T_END = 1.0
CONTROLLERS = ("passive", "lqr", "smc")


def run_cases(
    d: Design,
    cases: Iterable[int] = THESIS_CASES,
    observer: str = "thesis",
    t_end: float = T_END,
    on_result: Callable | None = None,
    on_start: Callable | None = None,
) -> list[Table2Row]:
    """Simulate every (case, controller, saturation) and return the rows.

    The passive beam does not depend on the limit: it is simulated once and
    reported for both. ``on_start(case, controller, saturation)`` is called before each
    row, ``on_result(row, result)`` after it.
    """
    A, B, E, Cy = d.plant
    obs = d.observer(observer)
    rows: list[Table2Row] = []
    for case in cases:
        load = thesis_load(case)
        for name in CONTROLLERS:
            fb = d.feedback(name)
            res: SimulationResult | None = None
            for sat in (True, False):
                if on_start is not None:
                    on_start(case, name, sat)
                if res is None or name != "passive":
                    res = simulate(
                        A, B, E, Cy, obs, fb, load, t_end=t_end, v_max=V_LIMIT if sat else None
                    )
                row = Table2Row(
                    case,
                    name,
                    sat,
                    peak(res.y) * 1e3,
                    settling_time(res.t, res.y),
                    max_abs(res.voltage),
                )
                rows.append(row)
                if on_result is not None:
                    on_result(row, res)
    return rows


def _pct(ours: float, ref: float) -> str:
    return f"{100.0 * (ours - ref) / ref:+6.1f}%"


def format_table2(rows: list[Table2Row], t_end: float = T_END) -> str:
    """Table 2 with thesis value, ours and the difference per cell."""
    head = (
        f"{'case':>4} {'ctrl':>7} {'sat':>4} | {'peak [mm]':^25} | {'settling [s]':^27} | "
        f"{'max |V| [V]':^25}"
    )
    sub = (
        f"{'':>4} {'':>7} {'':>4} | {'thesis':>7} {'ours':>7} {'diff':>8} | "
        f"{'thesis':>7} {'ours':>8} {'diff':>8} | {'thesis':>7} {'ours':>7} {'diff':>8}"
    )
    out = [head, sub, "-" * len(sub)]
    for r in rows:
        ref = thesis_row(r.case, r.controller, r.saturation)
        ts = f"{r.settling_s:8.4f}" if r.settling_s < t_end else f">{t_end:7.2f}"
        if ref is None:
            passive1 = r.case == 1 and r.controller == "passive"
            ref_pk = f"{PASSIVE_CASE1_PEAK_MM:.3f}" if passive1 else "-"
            d_pk = _pct(r.peak_mm, PASSIVE_CASE1_PEAK_MM) if passive1 else ""
            out.append(
                f"{r.case:>4} {r.controller:>7} {('on' if r.saturation else 'off'):>4} | "
                f"{ref_pk:>7} {r.peak_mm:7.3f} {d_pk:>8} | {'-':>7} {ts} {'':>8} | "
                f"{'-':>7} {r.max_voltage_V:7.0f} {'':>8}"
            )
            continue
        out.append(
            f"{r.case:>4} {r.controller:>7} {('on' if r.saturation else 'off'):>4} | "
            f"{ref.peak_mm:7.3f} {r.peak_mm:7.3f} {_pct(r.peak_mm, ref.peak_mm):>8} | "
            f"{ref.settling_s:7.4f} {ts} {_pct(r.settling_s, ref.settling_s):>8} | "
            f"{ref.max_voltage_V:7.0f} {r.max_voltage_V:7.0f} "
            f"{_pct(r.max_voltage_V, ref.max_voltage_V):>8}"
        )
    return "\n".join(out)
