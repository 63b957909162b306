"""Reference numbers from the thesis (Rodriguez 2006), with their provenance.

``TABLE2`` is the thesis's Table 2 (ch. 5, p. 48) with the maximum voltages
from the text of sections 5.3-5.5 (the saturated rows reach the 120 V limit).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from acld_gym.physics.actuator import V_LIMIT  # the saturated runs' limit (sec. 5.3)

__all__ = [
    "Table2Row",
    "TABLE2",
    "PASSIVE_CASE1_PEAK_MM",
    "FIRST_RESONANCE_RAD_S",
    "V_LIMIT",
    "thesis_row",
]

#: Passive (PCLD) peak tip deflection for case 1 [mm] (sec. 5.3, Fig. 9).
PASSIVE_CASE1_PEAK_MM = 0.675
#: First resonance used for load case 3 [rad/s] (sec. 5.5).
FIRST_RESONANCE_RAD_S = 179.0


@dataclass(frozen=True)
class Table2Row:
    """One row of Table 2: load case, controller, voltage limit on/off and the
    three metrics (peak [mm], 5% settling time [s], max |V| [V])."""

    case: int
    controller: str
    saturation: bool
    peak_mm: float
    settling_s: float
    max_voltage_V: float

    def as_dict(self) -> dict:
        return asdict(self)


TABLE2: tuple[Table2Row, ...] = (
    Table2Row(1, "lqr", True, 0.666, 0.3400, 120.0),
    Table2Row(1, "smc", True, 0.672, 0.3350, 120.0),
    Table2Row(1, "lqr", False, 0.594, 0.1125, 2380.0),
    Table2Row(1, "smc", False, 0.561, 0.0755, 2258.0),
    Table2Row(2, "lqr", True, 0.955, 0.4750, 120.0),
    Table2Row(2, "smc", True, 0.952, 0.4610, 120.0),
    Table2Row(2, "lqr", False, 0.624, 0.2250, 2445.0),
    Table2Row(2, "smc", False, 0.562, 0.1720, 2258.0),
    Table2Row(3, "lqr", True, 4.480, 0.9500, 120.0),
    Table2Row(3, "smc", True, 4.475, 0.9300, 120.0),
    Table2Row(3, "lqr", False, 1.145, 0.2980, 1622.0),
    Table2Row(3, "smc", False, 0.716, 0.2485, 1675.0),
)


def thesis_row(case: int, controller: str, saturation: bool) -> Table2Row | None:
    """The Table 2 row for a configuration, or None (e.g. passive)."""
    for r in TABLE2:
        if (r.case, r.controller, r.saturation) == (case, controller, saturation):
            return r
    return None
