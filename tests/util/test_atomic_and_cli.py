"""Issue 14, the command lines' hard edges: atomic result files, output paths checked
before computing, one-line errors instead of tracebacks, closed pipes."""

from __future__ import annotations

import json
import os
import resource
import runpy
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from acld_gym.util.atomic import check_writable, write_atomic, write_json

ROOT = Path(__file__).resolve().parents[2]


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "result.json"
    write_json(path, {"good": True})

    def half_then_fail(fh):
        fh.write(b'{"trunc')
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        write_atomic(path, half_then_fail)
    assert json.loads(path.read_text()) == {"good": True}
    assert [p.name for p in tmp_path.iterdir()] == ["result.json"]


def _limit_file_size():  # ulimit -f 1 (KB), with EFBIG instead of the killing signal
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (1024, 1024))


def test_file_size_limit_midway_keeps_the_previous_result(tmp_path):
    path = tmp_path / "model.json"
    path.write_text('{"previous": "result"}\n')
    out = subprocess.run(
        [sys.executable, "-m", "acld_gym.thesis.cli", "model", "--json", str(path)],
        capture_output=True,
        text=True,
        preexec_fn=_limit_file_size,
        cwd=ROOT,
    )
    assert out.returncode == 1  # the JSON (several KB) cannot be written
    lines = out.stderr.strip().splitlines()  # one line naming the file, no traceback
    assert len(lines) == 1 and lines[0].startswith(f"acld-gym: error: {path}: "), out.stderr
    assert json.loads(path.read_text()) == {"previous": "result"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.json"]


def test_run_main_turns_a_failed_file_operation_into_one_line(tmp_path, capsys):
    """An OSError with its file (an open that fails) and one without (a write to an open
    file on a full disk, where the writer's ``path`` names it); a damaged input file."""
    from acld_gym.util.atomic import write_text
    from acld_gym.util.validate import DataFileError, run_main

    def unreadable():
        return len((tmp_path / "missing.json").read_text())

    target = tmp_path / "out.md"

    def full_disk():
        def write(fh):
            raise OSError(28, "No space left on device")

        return write_atomic(target, write)

    def damaged():
        raise DataFileError(f"{tmp_path / 'r.json'}: algorithms: expected a mapping")

    assert run_main(unreadable, "cmd") == 1
    assert (
        capsys.readouterr().err
        == f"cmd: error: {tmp_path / 'missing.json'}: No such file or directory\n"
    )
    assert run_main(full_disk, "cmd") == 1
    assert capsys.readouterr().err == f"cmd: error: {target}: No space left on device\n"
    assert not target.exists() and list(tmp_path.iterdir()) == []
    assert run_main(damaged, "cmd") == 2
    assert (
        capsys.readouterr().err
        == f"cmd: error: {tmp_path / 'r.json'}: algorithms: expected a mapping\n"
    )
    write_text(target, "ok")
    assert run_main(lambda: 0, "cmd") == 0 and capsys.readouterr().err == ""
    with pytest.raises(ZeroDivisionError):  # a bug is not an input error: its traceback stays
        run_main(lambda: 1 / 0, "cmd")


def test_run_main_ctrl_c_is_one_line_and_status_130(capsys):
    """Ctrl-C during a command: one line, exit status 130, no traceback."""
    from acld_gym.util.validate import run_main

    def interrupted():
        raise KeyboardInterrupt

    assert run_main(interrupted, "cmd") == 130
    assert capsys.readouterr().err == "cmd: interrupted\n"


@pytest.mark.parametrize(
    "module, args",
    [
        ("baselines.evaluate", ["--json"]),
        ("acld_gym.thesis.cli", ["reproduce", "--json"]),
        ("train.compare", ["--json"]),
        ("acld_gym.thesis.cli", ["mesh", "--json"]),
    ],
)
def test_unwritable_output_fails_before_computing(module, args, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    t0 = time.perf_counter()
    out = subprocess.run(
        [sys.executable, "-m", module, *args, str(blocker / "out.json")],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "--json" in out.stderr and "not a directory" in out.stderr
    assert time.perf_counter() - t0 < 30  # refused up front, not after the computing


def test_check_writable_names_the_problem(tmp_path):
    with pytest.raises(ValueError, match="is a directory"):
        check_writable(tmp_path, "--json")
    check_writable(tmp_path / "new" / "deep" / "x.json", "--json")  # creatable: fine


_HEAD = "algo: ppo\ntimesteps: 10\nn_envs: 2\n"
CONFIGS = {
    "malformed YAML": ("n_envs: [1,\n", "YAML"),
    "learning_rate: fast": (
        _HEAD + "model: {policy: MlpPolicy, learning_rate: fast}\n",
        "learning_rate",
    ),
    "misspelled key": (_HEAD + "model: {policy: MlpPolicy, n_stepz: 3}\n", "n_stepz"),
    "shaping .inf": (_HEAD + "shaping: .inf\nmodel: {policy: MlpPolicy}\n", "shaping"),
}


def _python_m_train(argv, monkeypatch, capsys) -> tuple[int, str]:
    """``python -m train ARGV`` run as the interpreter runs it (``train/__main__.py`` as
    ``__main__``), in this process: its exit status and stderr. A traceback would escape
    as the exception itself, not as ``SystemExit``."""
    monkeypatch.setattr(sys, "argv", ["train", *argv])
    monkeypatch.chdir(ROOT)
    with pytest.raises(SystemExit) as exit_:
        runpy.run_module("train", run_name="__main__", alter_sys=True)
    return exit_.value.code, capsys.readouterr().err


@pytest.mark.parametrize("case", sorted(CONFIGS))
def test_training_cli_bad_config_is_one_line_and_creates_nothing(
    case, tmp_path, monkeypatch, capsys
):
    text, word = CONFIGS[case]
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(text)
    out_dir = tmp_path / "run"
    argv = ["ppo", "--config", str(cfg), "--out", str(out_dir)]
    code, err = _python_m_train(argv, monkeypatch, capsys)
    assert code == 2 and "Traceback" not in err
    assert word in err.strip().splitlines()[-1]
    assert not out_dir.exists()


@pytest.mark.parametrize(
    "flags, word",
    [
        (["--param-noise", "inf"], "--param-noise"),
        (["--seed", "99999999999999999999"], "--seed"),
        (["--param-noise", "0.5"], "--param-noise"),
    ],
)
def test_training_cli_bad_flags(flags, word, tmp_path, monkeypatch, capsys):
    out_dir = tmp_path / "run"
    code, err = _python_m_train(["ppo", *flags, "--out", str(out_dir)], monkeypatch, capsys)
    assert code == 2 and "Traceback" not in err and word in err
    assert not out_dir.exists()


def test_the_training_command_in_its_own_process_is_one_line(tmp_path):
    """The entry point as a user runs it, once: the tests above run the same module in
    this process."""
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(CONFIGS["misspelled key"][0])
    out_dir = tmp_path / "run"
    res = subprocess.run(
        [sys.executable, "-m", "train", "ppo", "--config", str(cfg), "--out", str(out_dir)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "n_stepz" in res.stderr.strip().splitlines()[-1]
    assert not out_dir.exists()


def test_closed_pipe_is_quiet():
    res = subprocess.run(
        f"{sys.executable} -m acld_gym.thesis.cli params | head -1",
        shell=True,
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert res.stdout.startswith("| field") and "Traceback" not in res.stderr


def test_check_figure_path_wants_a_format_matplotlib_writes(tmp_path):
    from acld_gym.util.validate import check_figure_path

    assert check_figure_path(tmp_path / "fig.svg") == tmp_path / "fig.svg"
    assert check_figure_path(tmp_path / "fig") == tmp_path / "fig"  # no suffix: PNG
    for bad in ("fig.xyz", "fig.pgf"):  # unknown; pgf needs LaTeX
        with pytest.raises(ValueError, match="--plot: cannot draw .*expected a suffix"):
            check_figure_path(tmp_path / bad)
    (tmp_path / "d.png").mkdir()
    with pytest.raises(ValueError, match="is a directory"):
        check_figure_path(tmp_path / "d.png")


def test_arg_type_says_what_it_expected():
    import argparse

    from acld_gym.util.validate import arg_type

    for kind, text, word in ((int, "1e9", "an integer"), (float, "abc", "a real number")):
        with pytest.raises(argparse.ArgumentTypeError, match=f"expected {word}, got '{text}'"):
            arg_type(kind, 1)(text)
    with pytest.raises(argparse.ArgumentTypeError, match=r"expected an integer in \[1, 5\]"):
        arg_type(int, 1, 5)("6")


def test_arg_dir_takes_a_folder_that_can_hold_files_and_names_why_not(tmp_path):
    """``arg_dir`` (the guide scripts' ``--save``): a folder there, or one that can be made,
    is returned as given and nothing is created; a file, or a path under one, is refused
    with the reason, whatever characters the path holds."""
    import argparse

    from acld_gym.util.validate import arg_dir

    (tmp_path / "there").mkdir()
    for ok in (tmp_path / "new" / "deeper", tmp_path / "there"):
        assert arg_dir(str(ok)) == str(ok)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["there"]  # "new" not made
    (tmp_path / "a (copy)").mkdir()
    (tmp_path / "a (copy)" / "file").write_text("x")
    file = tmp_path / "a (copy)" / "file"
    for bad, why in (
        (file, "it exists and is not a folder"),
        (file / "x", f"{str(file)!r} is not a folder"),
        (file / "x" / "y", f"{str(file)!r} is not a folder"),
    ):
        with pytest.raises(argparse.ArgumentTypeError) as err:
            arg_dir(str(bad))
        assert str(err.value) == f"expected a folder that can hold files, got {str(bad)!r}: {why}"


@pytest.mark.parametrize("size", [10, 100_000])  # flushed at the end / written in main
@pytest.mark.parametrize("unbuffered", ["", "1"])
def test_a_full_disk_under_stdout_redirection_is_one_line_naming_it(tmp_path, size, unbuffered):
    """``acld-gym params > file`` with no room: one line naming standard output, status 1
    (was Python's two-line 'Exception ignored ... OSError' at exit, status 120, or a line
    naming no file)."""
    import os
    import resource
    import subprocess
    import sys

    def no_room():
        resource.setrlimit(resource.RLIMIT_FSIZE, (0, resource.RLIM_INFINITY))

    code = "import sys; from acld_gym.util.validate import run_main; "
    code += f"sys.exit(run_main(lambda: print('x' * {size}) or 0, 'cmd'))"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    with open(tmp_path / "out.md", "wb") as out:
        run = subprocess.run(
            [sys.executable, "-c", code],
            stdout=out,
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=no_room,
            timeout=120,
            env=env | ({"PYTHONUNBUFFERED": unbuffered} if unbuffered else {}),
        )
    assert (run.returncode, run.stderr) == (1, "cmd: error: standard output: File too large\n")
