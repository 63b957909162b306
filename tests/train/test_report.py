"""The benchmark's tables in the docs are generated from the committed per-seed results
(``python -m train.bench.report train/benchmark/results-v1.json --write docs/training.md``)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from train.bench.report import BEGIN, GOALS, main, markdown, replace_block

RESULTS = Path("train/benchmark/results-v1.json")
PAGE = Path("docs/training.md")


def test_docs_tables_are_the_committed_results():
    summary = json.loads(RESULTS.read_text())
    text = PAGE.read_text()
    assert replace_block(text, markdown(summary), str(RESULTS), str(PAGE)) == text


def test_committed_results_hold_every_seed_and_the_goals():
    summary = json.loads(RESULTS.read_text())
    seeds = {"vrs": [0, 1, 2, 3, 4], "ppo": [0, 1, 2, 3, 4], "sac": [0, 1, 2, 3, 4]}
    for name, expected in seeds.items():
        a = summary["algorithms"][name]
        assert a["seeds"] == expected, name
        assert set(a["goals"]) == set(GOALS)
        for s in a["per_seed"]:
            assert all(0 < s[c] < 10 for c in ("1", "2", "3", "random"))


def test_write_replaces_only_the_block(tmp_path, capsys):
    page = tmp_path / "page.md"
    begin = BEGIN.format(src=RESULTS, dst=page)
    page.write_text(f"# head\n{begin}\nold\n<!-- benchmark-tables:end -->\ntail\n")
    assert main([str(RESULTS), "--write", str(page)]) == 0
    out = page.read_text()
    assert out.startswith("# head\n") and out.endswith("tail\n") and "old" not in out
    assert markdown(json.loads(RESULTS.read_text())) in out
    capsys.readouterr()
    page.write_text("no markers\n")
    with pytest.raises(SystemExit) as e:
        main([str(RESULTS), "--write", str(page)])
    assert e.value.code == 2 and "expected one" in capsys.readouterr().err
    assert page.read_text() == "no markers\n"  # left intact
