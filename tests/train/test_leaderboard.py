"""The leaderboard page and the README block are generated from the committed data
(``results/*.json``) and regenerate exactly; a hand edit fails ``render --check``; a
malformed results file is one line naming the file and the field, and nothing is written
(``python -m train.leaderboard``, issue 67). Fast: no simulation."""

from __future__ import annotations

import copy
import json
import math
import re
import shutil
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from acld_gym.util.validate import run_main
from tests.train.leaderboard_cli import PROG, run
from train.leaderboard.cli import main
from train.leaderboard.collect import merge, seed_stats, write_level
from train.leaderboard.readme import END, START, readme_block, replace_block
from train.leaderboard.render import GOAL_MARGIN, goal_lines, page, read_levels
from train.leaderboard.schema import CASES, EFFORT_CASES, check_level, empty_level, read_level

ROOT = Path(__file__).resolve().parents[2]
RESULTS, PAGE, README = ROOT / "results", ROOT / "docs" / "leaderboard.md", ROOT / "README.md"


# --- the committed data ------------------------------------------------------------


def test_the_committed_data_hold_the_references_of_the_seeded_levels():
    levels = read_levels(RESULTS)
    assert {"ACLDBeam-v0", "ACLDBeam-v1", "ACLDBeamLab-v1", "ACLDBeamHard-v1"} <= set(levels)
    for env_id, level in levels.items():
        refs = level["references"]["policies"]
        kinds = {e["kind"] for e in refs.values()}
        assert {"engineer's design", "plant oracle", "clairvoyant (1)"} <= kinds, env_id
        assert refs["passive"]["score"]["iqm"] == 0.0 and refs["bound"]["score"]["iqm"] == 1.0
        assert all(refs["lqr"]["ise_rel_lqr"][c] == 1.0 for c in CASES)
        assert all(e["score"]["n_episodes"] == 100 for e in refs.values()), env_id
        # the clairvoyant bound is below every causal policy on every ISE column
        for c in CASES:
            bound = refs["bound"]["ise_rel_lqr"][c]
            assert all(bound <= e["ise_rel_lqr"][c] * (1 + 1e-9) for e in refs.values())


def test_render_reads_the_levels_files_only_beside_make_runs_outputs(tmp_path):
    """``make run`` writes ``baselines.json``, ``compare.json`` and ``table2.json`` into
    ``results/`` beside the levels' files: the leaderboard reads ``<env id>.json`` of the
    registered ids and nothing else (it had refused ``baselines.json``, a list, after a
    ``make run``)."""
    for env_id in ("ACLDBeam-v1", "ACLDBeamLab-v1"):
        shutil.copy(RESULTS / f"{env_id}.json", tmp_path)
    (tmp_path / "baselines.json").write_text('[{"case": 1, "policy": "passive"}]')
    (tmp_path / "compare.json").write_text("{}")
    (tmp_path / "ACLDBeam-v9.json").write_text("{}")  # no such id: not a level
    assert sorted(read_levels(tmp_path)) == ["ACLDBeam-v1", "ACLDBeamLab-v1"]
    assert read_levels(tmp_path) == {
        k: v for k, v in read_levels(RESULTS).items() if k in ("ACLDBeam-v1", "ACLDBeamLab-v1")
    }


def test_render_regenerates_the_committed_page_and_readme_block_exactly(capsys):
    levels = read_levels(RESULTS)
    assert page(levels) == PAGE.read_text(encoding="utf-8")
    readme = README.read_text(encoding="utf-8")
    assert readme.count(START) == 1 and readme.count(END) == 1
    assert replace_block(readme, readme_block(levels), README) == readme
    code, out, err = run(
        ["render", "--check", "--results", RESULTS, "--page", PAGE, "--readme", README], capsys
    )
    assert (code, err) == (0, ""), err


def _digit_positions(text: str) -> list[int]:
    """Where the digits of the page's table rows are."""
    out, pos = [], 0
    for line in text.splitlines(keepends=True):
        if line.startswith("| `"):
            out += [pos + m.start() for m in re.finditer(r"\d", line)]
        pos += len(line)
    return out


@settings(max_examples=8, deadline=None)
@given(data=st.data())
def test_a_hand_edit_of_one_number_fails_the_check(tmp_path_factory, data):
    text = PAGE.read_text(encoding="utf-8")
    positions = _digit_positions(text)
    assert len(positions) > 100
    i = data.draw(st.sampled_from(positions))
    new = str((int(text[i]) + data.draw(st.integers(1, 9))) % 10)
    tmp = tmp_path_factory.mktemp("page")
    edited = tmp / "leaderboard.md"
    edited.write_text(text[:i] + new + text[i + 1 :], encoding="utf-8")
    readme = tmp / "README.md"
    shutil.copy(README, readme)
    argv = ["render", "--check", "--results", RESULTS, "--readme", readme, "--page", edited]
    code, out, err = main_check(argv)
    assert code == 1 and len(err.splitlines()) == 1 and str(edited) in err, err
    assert edited.read_text(encoding="utf-8") != text  # --check writes nothing


def main_check(argv) -> tuple[int, str, str]:
    """:func:`tests.train.leaderboard_cli.run` without capsys (hypothesis runs many
    examples in one test)."""
    import contextlib
    import io

    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        code = run_main(lambda: main([str(a) for a in argv]), PROG)
    return code, out.getvalue(), err.getvalue()


def test_a_hand_edit_of_the_readme_block_fails_the_check(tmp_path, capsys):
    readme = tmp_path / "README.md"
    text = README.read_text(encoding="utf-8")
    block = text[text.index(START) : text.index(END)]
    m = re.search(r"\d\.\d{3}", block)
    assert m is not None
    edited = block[: m.start()] + f"{float(m.group()) + 0.001:.3f}" + block[m.end() :]
    readme.write_text(text.replace(block, edited), encoding="utf-8")
    argv = ["render", "--check", "--results", RESULTS, "--page", PAGE, "--readme", readme]
    code, out, err = run(argv, capsys)
    assert code == 1 and len(err.splitlines()) == 1 and str(readme) in err


def test_render_writes_both_files_and_then_checks_clean(tmp_path, capsys):
    readme = tmp_path / "README.md"
    readme.write_text(f"before\n{START}\nold\n{END}\nafter\n", encoding="utf-8")
    out_page = tmp_path / "docs" / "leaderboard.md"
    out_page.parent.mkdir()
    argv = ["render", "--results", RESULTS, "--page", out_page, "--readme", readme]
    assert run(argv, capsys)[0] == 0
    assert out_page.read_text(encoding="utf-8") == PAGE.read_text(encoding="utf-8")
    text = readme.read_text(encoding="utf-8")
    assert text.startswith("before\n") and text.endswith("after\n") and "old" not in text
    assert run([*argv, "--check"], capsys)[0] == 0


def test_a_readme_without_the_markers_is_one_line(tmp_path, capsys):
    readme = tmp_path / "README.md"
    readme.write_text("no markers\n", encoding="utf-8")
    argv = ["render", "--results", RESULTS, "--page", tmp_path / "p.md", "--readme", readme]
    code, _, err = run(argv, capsys)
    assert code == 2 and len(err.splitlines()) == 1 and "leaderboard:start" in err
    assert not (tmp_path / "p.md").exists()


# --- malformed results files ---------------------------------------------------------


def synthetic_level(env_id="ACLDBeam-v1", engineer=0.75, algos=None) -> dict:
    """A valid level: passive, LQR, SMC, an engineer's design, the oracle, the bound, and
    the algorithms ``algos`` (name -> list of per-seed scores)."""

    def entry(kind, score, rel):
        return {
            "kind": kind,
            "score": {
                "version": 2,
                "iqm": score,
                "ci_low": score - 0.03,
                "ci_high": score + 0.03,
                "n_episodes": 100,
                "test_set": f"{env_id}/test-v1",
            },
            "ise_rel_lqr": dict.fromkeys(CASES, rel),
            "effort": {
                c: {"settled_rms_voltage_V": 3.5, "settled_limit_fraction": 0.0}
                for c in EFFORT_CASES
            },
        }

    prov = {
        "commands": ["x"],
        "acld_gym": "0",
        "git_commit": None,
        "date": "d",
        "machine": {"cpu": "c", "cores": 2},
    }
    policies = {
        "passive": entry("passive beam (0)", 0.0, 1.7),
        "lqr": entry("thesis, delay-free", 0.69, 1.0),
        "smc": entry("thesis, delay-free", 0.70, 0.99),
        "lqg": entry("engineer's design", engineer, 0.96),
        "mpc_oracle": entry("plant oracle", 0.76, 0.95),
        "bound": entry("clairvoyant (1)", 1.0, 0.7),
    }
    level = merge(empty_level(env_id), {"provenance": prov, "policies": policies})
    agents = {}
    for name, scores in (algos or {}).items():
        seeds = []
        for i, s in enumerate(scores):
            e = entry("", s, 0.97 if s >= 0.73 else 1.01)
            del e["kind"]
            seeds.append(
                {
                    **e,
                    "seed": i,
                    "steps": 10,
                    "budget": 10,
                    "train_seconds": 60.0 + i,
                    "train_cpu_seconds": None,
                    "runs": 1,
                    "retries": [],
                }
            )
        agents[name] = {
            "algo": name,
            "benchmark": "b",
            "provenance": prov,
            "seeds": seeds,
            "iqm": seed_stats(seeds),
        }
    return check_level(merge(level, agents=agents), f"{env_id}.json")


def test_the_goal_line_is_computed_from_the_data():
    target = 0.75 - GOAL_MARGIN
    level = synthetic_level(algos={"ppo": [target + 0.001] * 3, "sac": [target - 0.001] * 3})
    lines = goal_lines(level)
    assert f"{target:.3f}" in lines[0]
    (ppo,) = [x for x in lines if x.startswith("- `ppo`")]
    (sac,) = [x for x in lines if x.startswith("- `sac`")]
    assert "reaches it" in ppo and "3 of 3 seeds beat" in ppo
    assert "does not reach it" in sac and "0 of 3 seeds beat" in sac


def test_the_readme_block_names_what_has_no_data():
    level = synthetic_level(algos={"vrs": [0.74, 0.75]})
    block = readme_block({"ACLDBeam-v1": level})
    (row,) = [x for x in block.splitlines() if x.startswith("| `ACLDBeam-v1`")]
    assert (
        row == "| `ACLDBeam-v1` | 0.750 (`lqg`) | 0.760 (`mpc_oracle`) | not run | not run "
        "| 0.745 (2 seeds) |"
    )
    (lab,) = [x for x in block.splitlines() if x.startswith("| `ACLDBeamLab-v1`")]
    assert lab.count("not run") == 5


def _nest(depth: int):
    v: list | dict = []
    for _ in range(depth):
        v = [v]
    return v


BAD = [  # (change of the parsed file, the field the line must name)
    (lambda d: d["references"]["policies"]["lqg"]["score"].update(iqm="0.7"), "score.iqm"),
    (lambda d: d["references"]["policies"]["lqg"].pop("effort"), "lqg.effort: missing"),
    (lambda d: d["references"]["policies"]["lqg"]["score"].update(iqm=math.nan), "score.iqm"),
    (lambda d: d["agents"]["ppo"]["iqm"]["score"].update(ci_high=math.inf), "ci_high"),
    (lambda d: d["agents"]["ppo"]["seeds"][0].update(runs=True), "seeds[0].runs"),
    (lambda d: d["agents"]["ppo"]["seeds"][1].update(seed=0), "distinct seeds"),
    (lambda d: d["references"]["policies"]["lqr"]["ise_rel_lqr"].update({"3": 0}), "ise_rel_lqr.3"),
    (lambda d: d.update(env_id="gym_module:Evil-v0"), "env_id"),
    (lambda d: d.update(env_id="ACLDBeamLab-v1"), "the file's name"),
    (lambda d: d.update(format=2), "format"),
    (lambda d: d["agents"]["ppo"]["provenance"].update(commands=[]), "commands"),
    (lambda d: d["agents"]["ppo"].update(extra=_nest(20)), "nested deeper"),
]


@pytest.mark.parametrize("change, field", BAD, ids=[f for _, f in BAD])
def test_a_malformed_results_file_is_one_line_naming_file_and_field(
    tmp_path, capsys, change, field
):
    data = copy.deepcopy(synthetic_level(algos={"ppo": [0.7, 0.72]}))
    change(data)
    results = tmp_path / "results"
    results.mkdir()
    bad = results / "ACLDBeam-v1.json"
    bad.write_text(json.dumps(data), encoding="utf-8")  # (NaN and inf as JSON's literals)
    readme = tmp_path / "README.md"
    readme.write_text(f"{START}\n{END}\n", encoding="utf-8")
    argv = ["render", "--results", results, "--page", tmp_path / "p.md", "--readme", readme]
    code, out, err = run(argv, capsys)
    assert code == 2 and out == "" and len(err.splitlines()) == 1, err
    assert err.startswith(f"{PROG}: error: {bad}: ") and field in err, err
    assert not (tmp_path / "p.md").exists() and readme.read_text() == f"{START}\n{END}\n"
    with pytest.raises(ValueError, match=re.escape(field)):
        read_level(bad)


@pytest.mark.parametrize("text", ["", "{", "[1, 2]", "\udcff", "null", "[" * 100_000])
def test_a_file_that_is_not_a_level_is_one_line(tmp_path, capsys, text):
    results = tmp_path / "results"
    results.mkdir()
    (results / "ACLDBeam-v1.json").write_text(text, encoding="utf-8", errors="surrogateescape")
    argv = ["render", "--results", results, "--page", tmp_path / "p.md", "--readme", README]
    code, _, err = run(argv, capsys)
    assert code == 2 and len(err.splitlines()) == 1 and "ACLDBeam-v1.json" in err, err


def test_collect_keeps_a_damaged_file_and_computes_nothing(tmp_path, capsys):
    results = tmp_path / "results"
    results.mkdir()
    bad = results / "ACLDBeam-v1.json"
    bad.write_text('{"format": 1}', encoding="utf-8")
    code, _, err = run(
        ["collect", "--env-id", "ACLDBeam-v1", "--references", "--results", results], capsys
    )
    assert code == 2 and len(err.splitlines()) == 1 and f"{bad}: env_id: missing" in err
    assert bad.read_text() == '{"format": 1}'


@pytest.mark.parametrize(
    "argv, says",
    [
        (["collect", "--env-id", "Nope-v0", "--references"], "--env-id must be one of"),
        (["collect", "--env-id", "ACLDBeam-v1"], "needs --references, --benchmark"),
        (["collect", "--env-id", "ACLDBeam-v1", "--references", "--algos", "ppo"], "--algos"),
        (["collect", "--env-id", "ACLDBeam-v1", "--benchmark", "/nonexistent"], "--benchmark"),
        (
            ["collect", "--env-id", "ACLDBeam-v1", "--references", "--score-episodes", "101"],
            "--score-episodes",
        ),
    ],
)
def test_bad_collect_arguments_are_one_line_before_any_computing(tmp_path, capsys, argv, says):
    code, _, err = run([*argv, "--results", tmp_path], capsys)
    assert code == 2 and says in err.splitlines()[-1], err
    assert list(tmp_path.iterdir()) == []


def test_write_level_sorts_keys_and_refuses_what_it_could_not_read(tmp_path):
    level = synthetic_level(algos={"vrs": [0.74, 0.75]})
    path = write_level(tmp_path / "ACLDBeam-v1.json", level)
    assert read_level(path) == json.loads(path.read_text())
    text = path.read_text()
    assert text.index('"agents"') < text.index('"env_id"') < text.index('"references"')
    level["references"]["policies"]["lqg"]["score"]["iqm"] = math.nan
    with pytest.raises(ValueError, match="score.iqm"):
        write_level(path, level)
    assert read_level(path)["references"]["policies"]["lqg"]["score"]["iqm"] == 0.75
