"""The benchmark's tables in the docs are generated from the committed per-seed results
(``python -m train.bench.report train/benchmark/results-v1.json --write docs/training.md``)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from train.bench.report import BEGIN, GOALS, curves_figure, main, markdown, replace_block

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


def test_a_restarted_recipe_shows_its_runs_and_the_returned_runs_curve():
    """SAC's recipe is three runs per seed (restarts: 3): the budget counts all three, the
    table says so, and the curve is the returned run's, ending at one run's steps."""
    summary = json.loads(RESULTS.read_text())
    sac = summary["algorithms"]["sac"]
    assert sac["restarts"] == 3 and sac["budget"] == 3 * sac["curve"][-1]["steps"]
    assert f"| sac (sac) | {sac['budget']:,} (3 runs) |" in markdown(summary)
    assert "(1 runs)" not in markdown(summary)


def test_a_recipe_that_retries_failed_runs_shows_the_most_and_each_seeds_runs():
    """PPO's recipe retries a run only if it failed (restart_above): the budget is the most
    a seed may take, and each seed's row says how many runs it took."""
    summary = json.loads(RESULTS.read_text())
    ppo = summary["algorithms"]["ppo"]
    assert ppo["restarts"] == 3 and ppo["restart_above"] == "lqr"
    assert ppo["budget"] / 3 <= ppo["curve"][-1]["steps"] < ppo["budget"] / 2  # one run's
    text = markdown(summary)
    assert f"| ppo (ppo) | {ppo['budget']:,} (up to 3 runs) |" in text
    for s in ppo["per_seed"]:
        runs = f"{s['runs']} run" + ("s" if s["runs"] > 1 else "")
        assert f"| ppo | {s['seed']} ({runs}) |" in text
    assert "| sac | 0 |" in text  # every run of every seed: no count per seed
    two = {**ppo, "per_seed": [{**ppo["per_seed"][0], "runs": 2}]}
    assert "| ppo | 0 (2 runs) |" in markdown({**summary, "algorithms": {"ppo": two}})


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


def test_the_figure_marks_each_reported_result_at_its_budget():
    """A hollow diamond per algorithm and case at (budget, reported IQM): the selected
    checkpoint's for SAC (select:), which need not be the curve's last point."""
    import matplotlib.pyplot as plt

    summary = json.loads(RESULTS.read_text())
    fig = curves_figure(summary)
    try:
        assert len(fig.axes) == 8  # the whole runs, and the zoom on the end of training
        for ax, case in zip(fig.axes, ("1", "2", "3", "random") * 2, strict=True):
            marks = {
                (x, y)
                for line in ax.get_lines()
                if line.get_marker() == "D"
                for x, y in zip(line.get_xdata(), line.get_ydata(), strict=True)
            }
            for a in summary["algorithms"].values():
                assert (a["budget"], a["ise_rel_lqr"][case]["iqm"]) in marks
        for ax, case in zip(fig.axes[4:], ("1", "2", "3", "random"), strict=True):
            lo, hi = ax.get_ylim()  # the zoom holds LQR's level and every reported IQM
            assert lo < 1.0 < hi and ax.get_yscale() == "linear"
            for a in summary["algorithms"].values():
                assert lo < a["ise_rel_lqr"][case]["iqm"] < hi
        assert all(ax.get_yscale() == "log" for ax in fig.axes[:4])
        sac = summary["algorithms"]["sac"]
        assert sac["curve"][-1]["1"]["iqm"] != sac["ise_rel_lqr"]["1"]["iqm"]  # selected
    finally:
        plt.close(fig)


def test_plot_writes_the_figure_and_refuses_a_directory(tmp_path, capsys):
    assert main([str(RESULTS), "--plot", str(tmp_path / "f.png")]) == 0
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "wrote the learning curves" in capsys.readouterr().out
    with pytest.raises(SystemExit) as e:
        main([str(RESULTS), "--plot", str(tmp_path)])
    assert e.value.code == 2 and "--plot" in capsys.readouterr().err
