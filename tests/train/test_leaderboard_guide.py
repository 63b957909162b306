"""The guide's measured runs (``python -m train.leaderboard guide-run``, issue 69): a guide
script's command line is understood (client, level, seed, budget), its printed score is kept
as data exactly as :class:`train.scoring.PolicyScore` prints it, a failing or inconsistent
command records nothing, runs at once merge, and the page's block regenerates from the data
(a hand edit fails ``render --check``). Fast: the "scripts" here print a score line."""

from __future__ import annotations

import json
import re
import shutil
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from acld_gym.util.validate import DataFileError
from baselines.evaluation.score import Score
from tests.train.leaderboard_cli import run
from train.leaderboard.guide import (
    CLIENTS,
    GUIDE_FILE,
    guide_run,
    merge_run,
    parse_command,
    parse_score,
    read_runs,
    record,
)
from train.leaderboard.guide_page import END, START, guide_block
from train.leaderboard.render import beats, read_levels
from train.scoring import PolicyScore

ROOT = Path(__file__).resolve().parents[2]
RESULTS, GUIDE = ROOT / "results", ROOT / "docs" / "any-library.md"


def _line(env_id="ACLDBeamLab-v1", n=100, iqm=0.7025, rel=(0.259, 0.261, 0.925, 0.605)) -> str:
    """The line :class:`train.scoring.PolicyScore` prints, made by its own ``__str__``."""
    score = Score(iqm, iqm - 0.02, iqm + 0.02, n, f"{env_id}/test-v1", np.zeros(n), np.ones(n))
    return str(
        PolicyScore(
            score,
            dict(zip((1, 2, 3, "random"), rel, strict=True)),
            dict.fromkeys((1, 2, 3, "random"), 1.0),
            env_id,
        )
    )


@pytest.mark.parametrize(
    "argv, expected",
    [
        (
            ["python", "docs/examples/sb3_ppo.py", "ACLDBeamLab-v1", "--seed", "3"],
            ("SB3 PPO", "ACLDBeamLab-v1", 3, 2_000_000),
        ),
        (
            ["python", "docs/examples/sb3_sac.py", "--timesteps", "1000"],
            ("SB3 SAC", "ACLDBeam-v1", 0, 1000),
        ),
        (
            ["/opt/x/bin/python3.11", "ppo_continuous_action.py", "--env-id", "ACLDBeamHard-v1",
             "--seed=7", "--no-cuda", "--total-timesteps", "5000"],
            ("CleanRL PPO", "ACLDBeamHard-v1", 7, 5000),
        ),
        (["python", "ppo_continuous_action.py"], ("CleanRL PPO", "ACLDBeam-v1", 1, 1_000_000)),
    ],
)  # fmt: skip
def test_a_guide_command_is_understood(argv, expected):
    client, what = parse_command(argv)
    assert (client.label, what["env_id"], what["seed"], what["timesteps"]) == expected
    assert what["command"].startswith("python ") and Path(argv[1]).name in what["command"]


def test_a_script_of_this_checkout_is_recorded_relative_to_it():
    _, what = parse_command(["python", str(ROOT / "docs/examples/sb3_ppo.py"), "--seed", "1"])
    assert what["command"] == "python docs/examples/sb3_ppo.py --seed 1"


@pytest.mark.parametrize(
    "argv, says",
    [
        (["python", "train.py"], "expected a guide script"),
        (["python", "sb3_ppo.py", "ACLDBeam-v9"], "ACLDBeam-v9"),
        (["python", "sb3_ppo.py", "--seed", "x"], "--seed"),
    ],
)
def test_a_bad_command_is_one_line_before_it_runs(argv, says, tmp_path, capsys):
    code, out, err = run(["guide-run", "--results", tmp_path, "--", *argv], capsys)
    assert code == 2 and says in err.splitlines()[-1], err
    assert not (tmp_path / GUIDE_FILE).exists()


@pytest.mark.parametrize("n", [100, 7])
def test_the_score_line_is_read_as_printed(n):
    got = parse_score("training ...\n" + _line(n=n) + "\n")
    assert got["env_id"] == "ACLDBeamLab-v1"
    assert got["score"] == {
        "version": 2,
        "iqm": 0.7025,
        "ci_low": 0.6825,
        "ci_high": 0.7225,
        "n_episodes": n,
        "test_set": "ACLDBeamLab-v1/test-v1",
    }
    assert got["ise_rel_lqr"] == {"1": 0.259, "2": 0.261, "3": 0.925, "random": 0.605}
    with pytest.raises(ValueError, match="no score line"):
        parse_score("training ...\nscore v2 on nothing\n")


def test_a_score_line_of_another_level_is_refused():
    with pytest.raises(ValueError, match="ACLDBeam-v1 but its score line is on ACLDBeamLab"):
        record(["python", "sb3_ppo.py"], _line(), 1.0, [])


def _script(folder: Path, name: str, body: str) -> Path:
    path = folder / name
    path.write_text(body)
    return path


def test_guide_run_records_a_run_and_replaces_the_same_run(tmp_path, capsys):
    body = f"import time; print('training'); time.sleep(0.3); print({_line()!r})\n"
    script = _script(tmp_path, "sb3_ppo.py", body)
    argv = [sys.executable, script, "ACLDBeamLab-v1", "--seed", "5"]
    code, out, err = run(["guide-run", "--results", tmp_path / "r", "--", *argv], capsys)
    assert (code, err) == (0, ""), err
    assert "training" in out and "kept in" in out.splitlines()[-1]
    (rec,) = read_runs(tmp_path / "r" / GUIDE_FILE)
    assert (rec["client"], rec["env_id"], rec["seed"], rec["timesteps"]) == (
        "SB3 PPO", "ACLDBeamLab-v1", 5, 2_000_000,
    )  # fmt: skip
    assert rec["command"] == f"python {script} ACLDBeamLab-v1 --seed 5"
    assert rec["wall_seconds"] >= 0.3 and len(rec["load"]) == 2  # timed: the sleep is in it
    # the same client, level, seed and budget again: replaced, not added
    _script(tmp_path, "sb3_ppo.py", f"print({_line(iqm=0.6)!r})\n")
    assert run(["guide-run", "--results", tmp_path / "r", "--", *argv], capsys)[0] == 0
    (rec,) = read_runs(tmp_path / "r" / GUIDE_FILE)
    assert rec["score"]["iqm"] == 0.6


@pytest.mark.parametrize(
    "body, says",
    [
        ("import sys; print('x'); sys.exit(3)", "exited with 3"),
        ("print('no score')", "no score line"),
        (f"print({_line(env_id='ACLDBeam-v0')!r})", "score line is on ACLDBeam-v0"),
    ],
)
def test_a_failed_run_records_nothing(body, says, tmp_path, capsys):
    results = tmp_path / "r"
    script = _script(tmp_path, "sb3_sac.py", f"print({_line()!r})\n")
    good = [sys.executable, script, "ACLDBeamLab-v1"]
    assert run(["guide-run", "--results", results, "--", *good], capsys)[0] == 0
    before = (results / GUIDE_FILE).read_bytes()
    bad = _script(tmp_path, "sb3_ppo.py", body)
    argv = ["guide-run", "--results", results, "--", sys.executable, bad, "ACLDBeamLab-v1"]
    code, out, err = run(argv, capsys)
    assert code == 1 and len(err.splitlines()) == 1 and says in err, err
    assert (results / GUIDE_FILE).read_bytes() == before


def test_runs_at_once_each_keep_their_record(tmp_path):
    """Two runs that end together both land: each merges into what the other wrote."""
    results = tmp_path / "r"
    script = _script(tmp_path, "sb3_ppo.py", f"import time; time.sleep(0.3); print({_line()!r})\n")
    sink = open(tmp_path / "out.txt", "w")
    threads = [
        threading.Thread(
            target=guide_run,
            args=([sys.executable, str(script), "ACLDBeamLab-v1", "--seed", str(s)], results, sink),
        )
        for s in range(4)
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    sink.close()
    assert sorted(r["seed"] for r in read_runs(results / GUIDE_FILE)) == [0, 1, 2, 3]


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda d: d.update(format=2), "format"),
        (lambda d: d["runs"][0].update(client="SB3 TD3"), "runs[0].client"),
        (lambda d: d["runs"][0].update(env_id="os.system"), "runs[0].env_id"),
        (lambda d: d["runs"][0]["score"].update(iqm="0.7"), "runs[0].score.iqm"),
        (lambda d: d["runs"][0]["ise_rel_lqr"].pop("random"), "runs[0].ise_rel_lqr.random"),
        (lambda d: d["runs"].append(d["runs"][0]), "runs"),
    ],
)
def test_a_damaged_guide_file_is_one_line_naming_the_field(edit, field, tmp_path):
    rec = record(["python", "sb3_ppo.py", "ACLDBeamLab-v1"], _line(), 3.0, [1.0, 2.0])
    data = {"format": 1, "runs": [rec]}
    edit(data)
    path = tmp_path / "runs.json"
    path.write_text(json.dumps(data))
    with pytest.raises(DataFileError) as exc:
        read_runs(path)
    assert str(path) in str(exc.value) and field in str(exc.value)
    assert len(str(exc.value).splitlines()) == 1


def _argv(name: str, env_id: str, seed: int) -> list[str]:
    level = ["--env-id", env_id] if name == "ppo_continuous_action.py" else [env_id]
    return ["python", name, *level, "--seed", str(seed)]


def test_merge_orders_by_client_level_and_seed():
    recs = [
        record(_argv(name, env, seed), _line(env_id=env), 1.0, [])
        for name, env, seed in [
            ("ppo_continuous_action.py", "ACLDBeam-v1", 1),
            ("sb3_sac.py", "ACLDBeamLab-v1", 2),
            ("sb3_ppo.py", "ACLDBeamLab-v1", 9),
            ("sb3_ppo.py", "ACLDBeam-v1", 4),
        ]
    ]
    runs: list[dict] = []
    for r in recs:
        runs = merge_run(runs, r)
    assert [(r["client"], r["env_id"], r["seed"]) for r in runs] == [
        ("SB3 PPO", "ACLDBeam-v1", 4),
        ("SB3 PPO", "ACLDBeamLab-v1", 9),
        ("SB3 SAC", "ACLDBeamLab-v1", 2),
        ("CleanRL PPO", "ACLDBeam-v1", 1),
    ]


def test_beats_compares_with_the_thesis_lqr_and_smc():
    smc = {"1": 0.95, "2": 1.2, "3": 1.0, "random": 0.99}
    run_ = {"ise_rel_lqr": {"1": 0.94, "2": 0.999, "3": 5.0, "random": 0.991}}
    assert beats(run_, smc) == ["random"]  # case 3 is not a goal case
    assert beats(run_, None) is None
    run_["ise_rel_lqr"]["random"] = 0.5
    assert beats(run_, smc) == []


# --- the committed page ---------------------------------------------------------------


def _committed_runs() -> list[dict]:
    path = RESULTS / GUIDE_FILE
    return read_runs(path) if path.is_file() else []


def test_the_page_block_regenerates_exactly_from_the_committed_data(capsys):
    text = GUIDE.read_text(encoding="utf-8")
    block = guide_block(_committed_runs(), read_levels(RESULTS))
    assert text.count(START) == 1 and block in text
    paths = ["--results", RESULTS, "--page", ROOT / "docs" / "leaderboard.md"]
    paths += ["--readme", ROOT / "README.md", "--guide", GUIDE]
    code, out, err = run(["render", "--check", *paths], capsys)
    assert (code, err) == (0, ""), err


def test_a_hand_edit_of_the_page_block_fails_the_check(tmp_path, capsys):
    text = GUIDE.read_text(encoding="utf-8")
    block = text[text.index(START) : text.index(END)]
    m = re.search(r"\d\.\d{3}", block) or re.search(r"No run recorded", block)
    assert m is not None
    new = "9.999" if m.group()[0].isdigit() else "No runs recorded"
    edited = tmp_path / "any-library.md"
    edited.write_text(text.replace(block, block[: m.start()] + new + block[m.end() :]))
    page, readme = tmp_path / "p.md", tmp_path / "README.md"
    shutil.copy(ROOT / "docs" / "leaderboard.md", page)
    shutil.copy(ROOT / "README.md", readme)
    argv = ["render", "--check", "--results", RESULTS, "--page", page, "--readme", readme]
    argv += ["--guide", edited]
    code, out, err = run(argv, capsys)
    assert code == 1 and len(err.splitlines()) == 1 and str(edited) in err, err


def test_the_block_names_every_client_and_level_it_has_runs_of(tmp_path):
    levels = read_levels(RESULTS)
    runs: list[dict] = []
    for name in CLIENTS:
        argv = _argv(name, "ACLDBeamHard-v1", 3)
        runs = merge_run(runs, record(argv, _line(env_id="ACLDBeamHard-v1"), 60.0, [1.0, 2.0]))
    block = guide_block(runs, levels)
    for client in CLIENTS.values():
        assert f"| {client.label}, " in block
    assert block.count("| `ACLDBeamHard-v1` | 3 |") == 3  # one row per run (seed 3)
    assert "| 1.0, 2.0 |" in block and "not run" in block  # the load; the levels without runs
