"""Issue 65, deliverable 3: every training command validates its inputs before it computes
(env ids of this package only, output paths, every section of every config, resumed files),
and a failed file operation is one line naming the file, never a traceback.

The computing that must not start is replaced by a function that fails the test if called
(the references, a trial's training): a refusal is then proved to come before it.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest

import train.core.evaluate as evaluate
import train.core.trials as trials
from train.benchmark import main as benchmark_main
from train.cli import main as train_main

ROOT = Path(__file__).resolve().parents[2]
BAD_IDS = ["Nope", "CartPole-v1", "acld_gym:ACLDBeam-v1", "evil_agent:ACLDBeam-v1", ""]


@pytest.fixture
def no_computing(monkeypatch):
    """Fail the test if the references or a trial are computed."""

    def forbidden(*args, **kwargs):
        raise AssertionError("computed before the input was validated")

    monkeypatch.setattr(evaluate, "references", forbidden)
    monkeypatch.setattr(trials, "run_trial", forbidden)


def _refused(fn, argv, capsys, *words) -> str:
    with pytest.raises(SystemExit) as exit_:
        fn(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    last = err.strip().splitlines()[-1]
    assert "Traceback" not in err and all(w in last for w in words), last
    return last


@pytest.mark.parametrize("env_id", BAD_IDS)
def test_benchmark_refuses_an_env_id_not_of_this_package(env_id, tmp_path, capsys, no_computing):
    out = tmp_path / "b"
    argv = ["--algos", "vrs", "--seeds", "0", "--env-id", env_id, "--out", str(out)]
    _refused(benchmark_main, argv, capsys, "--env-id", "ACLDBeam-v1")
    assert not out.exists()


@pytest.mark.parametrize("env_id", BAD_IDS)
def test_train_refuses_an_env_id_not_of_this_package(env_id, tmp_path, capsys, no_computing):
    out = tmp_path / "t"
    _refused(train_main, ["vrs", "--env-id", env_id, "--out", str(out)], capsys, "--env-id")
    assert not out.exists()


def test_benchmark_refuses_an_out_that_is_a_file(tmp_path, capsys, no_computing):
    blocker = tmp_path / "file"
    blocker.write_text("keep")
    for out in (blocker, blocker / "sub"):
        _refused(benchmark_main, ["--algos", "vrs", "--out", str(out)], capsys, "--out")
    assert blocker.read_text() == "keep"


@pytest.mark.parametrize(
    "inside",
    ["trials", "agents", "results.json/", "references-ACLDBeam-v1.json/", "trials/vrs-s0.json/"],
)
def test_benchmark_checks_every_output_path_first(inside, tmp_path, capsys, no_computing):
    """A place the command writes that is in the way: a file where a folder goes, a folder
    (a trailing slash) where a file goes."""
    out = tmp_path / "b"
    spot = out / inside.rstrip("/")
    spot.parent.mkdir(parents=True, exist_ok=True)
    if inside.endswith("/"):
        spot.mkdir()
    else:
        spot.write_text("a file where a folder goes")
    _refused(benchmark_main, ["--algos", "vrs", "--seeds", "0", "--out", str(out)], capsys, "--out")


@pytest.mark.parametrize(
    "text, words",
    [
        ("base: vrs\nmodel: {step_sise: 0.05}\n", ("model", "step_sise")),
        ("base: vrs\nmodel: {top_directions: 99}\n", ("model.top_directions",)),
        ("base: vrs\nloads: {random: 0.5}\n", ("loads.random",)),
        ("base: sac\nmodel: {policy_kwargs: {net_arch: oops}}\n", ("model",)),
        ("base: sac\nmodel: {policy: NoSuchPolicy}\n", ("model",)),
        ("base: ppo\nmodel: {learning_rate: {linear: [1, 2, 3]}}\n", ("learning_rate",)),
        ("base: ppo\nselect: {episodes: 0, every: 10}\n", ("select.episodes",)),
        ("base: ppo\naverage: {begin: 5}\n", ("unknown key", "average")),
        ("base: ppo\nanneal_std: {start: 0, end: 2}\n", ("unknown key", "anneal_std")),
        ("base: ppo\ndistill: {teacher: oracle}\n", ("distill.teacher",)),
        ("base: ppo\nnormalize: {norm_obz: true}\n", ("normalize", "norm_obz")),
        ("base: ppo\nenv_kwargs: {param_noise: 7}\n", ("env_kwargs",)),
        ("algo: vrs\ntimesteps: [1\n", ("not valid YAML",)),
        ("base: nothing_of_that_name\n", ("base",)),
    ],
)
def test_benchmark_validates_every_config_section_before_the_references(
    text, words, tmp_path, capsys, no_computing
):
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(text)
    out = tmp_path / "b"
    _refused(benchmark_main, ["--config", str(cfg), "--out", str(out)], capsys, *words)
    assert not (out / "trials").exists()


def test_train_builds_the_algorithm_before_training(tmp_path, capsys, no_computing):
    cfg = tmp_path / "sac_bad.yaml"
    cfg.write_text("base: sac\nmodel: {policy_kwargs: {net_arch: oops}}\n")
    out = tmp_path / "t"
    _refused(train_main, ["sac", "--config", str(cfg), "--out", str(out)], capsys, "model")
    assert not out.exists()


def test_benchmark_options_are_checked(tmp_path, capsys, no_computing):
    base = ["--algos", "vrs", "--out", str(tmp_path / "b")]
    for extra, word in (
        (["--seeds", "1", "1"], "--seeds"),
        (["--seeds", "-3"], "--seeds"),
        (["--timesteps", "0"], "--timesteps"),
        (["--random-episodes", "21"], "--random-episodes"),
        (["--cpus-per-trial", "0"], "--cpus-per-trial"),
        (["--no-train"], "--resume"),
    ):
        _refused(benchmark_main, base + extra, capsys, word)


def _limit_file_size():  # ulimit -f 4 (KB); Python ignores SIGXFSZ, so a write gets EFBIG
    import resource

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))


def test_report_on_a_full_disk_writes_no_page_and_says_so_in_one_line(tmp_path):
    """Two pages, the second too large to write: neither changes (all or none), and the
    command ends with one line naming the file, exit status 1."""
    from train.core.report import MARK_BEGIN, MARK_END

    results = "studies/results-v1.json"
    pages = [tmp_path / "small.md", tmp_path / "large.md"]
    for page, filler in zip(pages, ("", "x" * 3000 + "\n"), strict=True):
        begin = MARK_BEGIN.format(kind="headline", src=results, dst=page)
        page.write_text(f"{filler}{begin}\nold\n{MARK_END.format(kind='headline')}\n")
    before = [p.read_text() for p in pages]
    res = subprocess.run(
        [sys.executable, "-m", "train.core.report", results, "--write", *map(str, pages)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        preexec_fn=_limit_file_size,
    )
    assert res.returncode == 1, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr
    assert lines[0].startswith("python -m train.core.report: error: ")
    assert str(pages[1]) in lines[0] and "too large" in lines[0].lower()
    assert [p.read_text() for p in pages] == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["large.md", "small.md"]


def test_report_writes_every_page(tmp_path):
    from train.core.report import MARK_BEGIN, MARK_END, main

    results = "studies/results-v1.json"
    pages = [tmp_path / "a.md", tmp_path / "b.md"]
    for page in pages:
        begin = MARK_BEGIN.format(kind="headline", src=results, dst=page)
        page.write_text(f"{begin}\nold\n{MARK_END.format(kind='headline')}\n")
    assert main([results, "--write", *map(str, pages)]) == 0
    assert all("random search" in p.read_text() and "old" not in p.read_text() for p in pages)


def test_report_refuses_a_page_without_markers_before_writing_any(tmp_path, capsys):
    from train.core.report import MARK_BEGIN, MARK_END, main

    results = "studies/results-v1.json"
    good, bad = tmp_path / "good.md", tmp_path / "bad.md"
    begin = MARK_BEGIN.format(kind="headline", src=results, dst=good)
    good.write_text(f"{begin}\nold\n{MARK_END.format(kind='headline')}\n")
    bad.write_text("no markers\n")
    _refused(main, [results, "--write", str(good), str(bad)], capsys, str(bad))
    assert "old" in good.read_text()


def test_report_names_a_missing_results_file(tmp_path, capsys):
    from train.core.report import main

    _refused(main, [str(tmp_path / "none.json")], capsys, "none.json", "No such file")


def test_resume_says_a_damaged_record_in_one_line(tmp_path, capsys, no_computing):
    out = tmp_path / "b"
    (out / "trials").mkdir(parents=True)
    rec = out / "trials" / "vrs-s0.json"
    rec.write_text('{"name": "vrs", "se')
    argv = ["--algos", "vrs", "--seeds", "0", "--resume", "--no-train", "--out", str(out)]
    with pytest.raises(SystemExit):
        benchmark_main(argv)
    said = capsys.readouterr().out.splitlines()
    assert any(str(rec) in line and "not valid JSON" in line and "again" in line for line in said)
    assert rec.read_text() == '{"name": "vrs", "se'  # nothing rewritten by a refused run


@pytest.mark.parametrize(
    "argv, word",
    [
        (["vrs", "--learning-rates", "0.1"], "learning_rate"),  # vrs has none
        (["ppo", "--seeds", "3", "3"], "--seeds"),
        (["ppo", "--learning-rates", "0.1", "0.1"], "--learning-rates"),
        (["ppo", "--learning-rates", "nan"], "--learning-rates"),
        (["ppo", "--learning-rates", "2"], "--learning-rates"),
        (["ppo", "--seeds", "99999999999"], "--seeds"),
    ],
)
def test_sweep_validates_before_starting_ray(argv, word, capsys, monkeypatch, no_computing):
    from train.sweep import main as sweep_main

    def forbidden(*args, **kwargs):
        raise AssertionError("Ray started before the input was validated")

    monkeypatch.setattr(trials, "init_ray", forbidden)
    _refused(sweep_main, argv, capsys, word)


def test_sweep_refuses_an_out_that_is_a_file(tmp_path, capsys, monkeypatch, no_computing):
    from train.sweep import main as sweep_main

    blocker = tmp_path / "file"
    blocker.write_text("keep")
    monkeypatch.setattr(trials, "init_ray", lambda *a: pytest.fail("Ray started"))
    _refused(sweep_main, ["vrs", "--out", str(blocker)], capsys, "--out")
    assert blocker.read_text() == "keep"


def test_benchmark_builds_the_training_env_on_the_env_id_first(tmp_path, capsys, no_computing):
    """The config's env options on top of the id's preset (here a fixed temperature against
    the hard level's drawn one) are refused before the references, naming the id."""
    cfg = tmp_path / "hot.yaml"
    cfg.write_text("base: vrs\nenv_kwargs: {temperature: 35}\n")
    argv = ["--config", str(cfg), "--env-id", "ACLDBeamHard-v1", "--out", str(tmp_path / "b")]
    _refused(benchmark_main, argv, capsys, str(cfg), "env_kwargs on ACLDBeamHard-v1")


def test_report_names_an_undecodable_page(tmp_path, capsys):
    from train.core.report import main

    page = tmp_path / "page.md"
    page.write_bytes(b"\xff\xfe binary")
    _refused(main, ["studies/results-v1.json", "--write", str(page)], capsys, str(page))
    assert page.read_bytes() == b"\xff\xfe binary"
