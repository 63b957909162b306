"""``docs/variants.md``'s score table (score v2 of every reference on each level) states the
numbers of ``results/<level>.json``, each rounded once to three decimals: the page, the
README and the leaderboard then agree (the page once said 0.756 where the file's 0.75655
gives 0.757)."""

from __future__ import annotations

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "variants.md"
LEVELS = ("ACLDBeam-v1", "ACLDBeamLab-v1", "ACLDBeamHard-v1")
HEAD = "| policy | what it is | " + " | ".join(LEVELS) + " |"
CELL = re.compile(r"^(-?\d\.\d{3})(?: \[(-?\d\.\d{3}), (-?\d\.\d{3})\])?$")


def table(text: str) -> dict[str, list[str]]:
    """``{policy: [cell per level]}`` of the page's score table."""
    rows = {}
    for line in text[text.index(HEAD) :].splitlines()[2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        rows[cells[0].strip("`")] = cells[2:]
    return rows


def mismatches(text: str) -> list[str]:
    """The cells that are not the results files' IQM [CI low, CI high] to 3 decimals."""
    rows = table(text)
    bad = [] if len(rows) == 8 else [f"{len(rows)} rows, expected 8: {list(rows)}"]
    for col, level in enumerate(LEVELS):
        results = json.loads((ROOT / "results" / f"{level}.json").read_text())
        for policy, cells in rows.items():
            score = results["references"]["policies"][policy]["score"]
            want = [f"{score[k]:.3f}" for k in ("iqm", "ci_low", "ci_high")]
            match = CELL.match(cells[col])
            got = [g for g in match.groups() if g is not None] if match else None
            if got is None or got != want[: len(got)]:
                bad.append(f"{policy} on {level}: page {cells[col]!r}, results {want}")
    return bad


def test_the_score_table_is_the_results_files():
    assert mismatches(PAGE.read_text()) == []


def test_a_wrong_digit_is_named():
    text = PAGE.read_text()
    wrong = text.replace(table(text)["mpc_oracle"][1], "0.756 [0.730, 0.785]", 1)
    [line] = mismatches(wrong)
    assert line.startswith("mpc_oracle on ACLDBeamLab-v1: page '0.756 [0.730, 0.785]'"), line
