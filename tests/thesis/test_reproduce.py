"""Acceptance tests of acld_gym.thesis.reproduce: the thesis's Table 2 (ch. 5).

Provenance:
* thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt: Table 2 (p. 48,
  values in acld_gym.thesis.table2.TABLE2), sec. 5.3 (passive case-1 peak 0.675 mm, 120 V
  limit), sec. 5.5 (first resonance 179 rad/s).
* The issue's acceptance tolerances: passive peak 2%, first frequency 1%; LQR peak 5%,
  settling 10%, unsaturated voltage 10%; SMC peak 5%, settling 20%.
"""

from __future__ import annotations

import numpy as np
import pytest

from acld_gym.design.pipeline import design
from acld_gym.design.simulate import simulate
from acld_gym.physics.loads import thesis_load
from acld_gym.thesis.reproduce import format_table2, run_cases
from acld_gym.thesis.table2 import (
    FIRST_RESONANCE_RAD_S,
    PASSIVE_CASE1_PEAK_MM,
    TABLE2,
    V_LIMIT,
    Table2Row,
    thesis_row,
)

KEYS = {"case", "controller", "saturation", "peak_mm", "settling_s", "max_voltage_V"}


@pytest.fixture(scope="module")
def d():
    return design()


@pytest.fixture(scope="module")
def rows(d):
    return run_cases(d)  # ~5-8 s: the full 18-row study


def _row(rows, case, ctrl, sat) -> Table2Row:
    (r,) = [r for r in rows if (r.case, r.controller, r.saturation) == (case, ctrl, sat)]
    return r


def test_rows_shape(rows):
    assert len(rows) == 18
    for r in rows:
        assert set(r.as_dict()) == KEYS
    combos = {(r.case, r.controller, r.saturation) for r in rows}
    assert len(combos) == 18


def test_passive_case1_peak(rows):
    # Thesis sec. 5.3: 0.675 mm (ours 0.684 mm, +1.3%).
    r = _row(rows, 1, "passive", False)
    assert r.peak_mm == pytest.approx(PASSIVE_CASE1_PEAK_MM, rel=0.02)
    assert r.max_voltage_V == 0.0
    assert _row(rows, 1, "passive", True) == Table2Row(
        1, "passive", True, r.peak_mm, r.settling_s, 0.0
    )


def test_first_damped_frequency(d):
    # Thesis sec. 5.5: 179 rad/s (ours 178.63).
    assert d.truth.natural_frequencies()[0] == pytest.approx(FIRST_RESONANCE_RAD_S, rel=0.01)


@pytest.mark.parametrize("case", [1, 2, 3])
@pytest.mark.parametrize("sat", [True, False])
def test_lqr_rows(rows, case, sat):
    r = _row(rows, case, "lqr", sat)
    ref = thesis_row(case, "lqr", sat)
    assert r.peak_mm == pytest.approx(ref.peak_mm, rel=0.05)
    assert r.settling_s == pytest.approx(ref.settling_s, rel=0.10)
    if sat:
        assert abs(r.max_voltage_V - V_LIMIT) <= 1e-9
    else:
        assert r.max_voltage_V == pytest.approx(ref.max_voltage_V, rel=0.10)


@pytest.mark.parametrize("case", [1, 2, 3])
@pytest.mark.parametrize("sat", [True, False])
def test_smc_rows(rows, case, sat):
    r = _row(rows, case, "smc", sat)
    ref = thesis_row(case, "smc", sat)
    assert r.peak_mm == pytest.approx(ref.peak_mm, rel=0.05)
    assert r.settling_s == pytest.approx(ref.settling_s, rel=0.20)
    if sat:
        assert abs(r.max_voltage_V - V_LIMIT) <= 1e-9


@pytest.mark.parametrize("case,v", [(1, 3179.0), (2, 3179.0), (3, 1741.0)])
def test_smc_unsaturated_voltage_regression(rows, case, v):
    # Regression on our measured values (3179.4, 3179.4, 1741.4 V). The thesis reports
    # 2258 V (cases 1, 2) and 1675 V (case 3): our maximum is the equivalent-control
    # peak at ~6.7 ms after the pulse (see the next test), which the thesis's plots/
    # sampling apparently did not catch; peaks and settling times do agree.
    assert _row(rows, case, "smc", False).max_voltage_V == pytest.approx(v, rel=0.02)


def test_smc_voltage_peak_time(d):
    A, B, E, Cy = d.plant
    res = simulate(A, B, E, Cy, d.observer("thesis"), d.smc, thesis_load(1), t_end=0.02, v_max=None)
    i = int(np.argmax(np.abs(res.voltage)))
    assert res.t[i] == pytest.approx(6.7e-3, abs=0.5e-3)
    assert abs(res.voltage[i]) == pytest.approx(3179.0, rel=0.02)


def test_every_table2_row_covered(rows):
    ours = {(r.case, r.controller, r.saturation) for r in rows}
    assert {(r.case, r.controller, r.saturation) for r in TABLE2} <= ours
    assert thesis_row(1, "passive", True) is None


def test_format_table2(rows):
    s = format_table2(rows)
    lines = s.splitlines()
    assert len(lines) == 3 + 18
    assert "0.675" in lines[3]
    assert "2380" in s and "2379" in s
