"""``python -m train.compare`` checks every argument before computing anything (issue 65):
an --agents that is not a directory (it used to run with no agents and compute the
references for minutes), a directory without agents, an --only that leaves the folder, a
--param-noise beyond the mesh's bound (it failed at the first episode), the same file for
--json and --markdown: one line naming the argument, exit status 2."""

from __future__ import annotations

import pytest

import train.compare as cmp


@pytest.fixture
def no_computing(monkeypatch):
    def fail(*args, **kwargs):
        raise AssertionError("computed before the arguments were checked")

    for name in ("reference_policies", "compare", "add_scores"):
        monkeypatch.setattr(cmp, name, fail)


def _refused(argv, capsys) -> str:
    with pytest.raises(SystemExit) as e:
        cmp.main(argv)
    err = capsys.readouterr().err
    assert e.value.code == 2 and "Traceback" not in err
    last = err.strip().splitlines()[-1]  # argparse's usage, then one line
    assert last.startswith("python -m train.compare: error: ")
    return last


@pytest.mark.usefixtures("no_computing")
@pytest.mark.parametrize(
    "case, word",
    [
        ("missing", "--agents: "),
        ("file", "--agents: "),
        ("empty", "--agents: no agent trained on --mesh converged"),
        ("only-parent", "--only: expected a folder name, got '../vrs'"),
        ("only-dot", "--only: expected a folder name, got '.'"),
        ("thesis-noise", "--param-noise: param_noise must be at most 0.05 for mesh='thesis'"),
        ("same-output", "--json and --markdown name the same file"),
        ("noise-range", "argument --param-noise: expected <= 0.1"),
    ],
)
def test_a_bad_argument_is_refused_before_computing(case, word, tmp_path, capsys):
    argv = {
        "missing": ["--agents", str(tmp_path / "nope")],
        "file": ["--agents", str(tmp_path / "f.txt")],
        "empty": ["--agents", str(tmp_path)],
        "only-parent": ["--only", "../vrs"],
        "only-dot": ["--only", "."],
        "thesis-noise": ["--mesh", "thesis", "--param-noise", "0.08"],
        "same-output": ["--json", str(tmp_path / "o"), "--markdown", str(tmp_path / "o")],
        "noise-range": ["--param-noise", "0.5"],
    }[case]
    (tmp_path / "f.txt").write_text("x")
    last = _refused(argv, capsys)
    assert word in last, last
    if case == "missing":
        assert "does not exist" in last
    if case == "file":
        assert "is not a directory" in last


def test_the_shipped_agents_pass_the_checks(no_computing, tmp_path):
    # the checks refuse nothing that works: the run reaches the computing (stubbed here)
    with pytest.raises(AssertionError, match="computed before"):
        cmp.main(["--only", "vrs", "--json", str(tmp_path / "a.json"), "--quiet"])
