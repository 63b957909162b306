"""Tests of acld_gym.util.progress and of the progress line of the long commands.

Provenance: the issue's rules (a bar per stage on a terminal: case, policy, episode k of n;
silent off a terminal and with ``--quiet``); tqdm's bar format "desc: ... n/total".
"""

from __future__ import annotations

import contextlib
import io
import re
import sys

import pytest

from acld_gym.util.progress import Progress


class FakeTerminal(io.StringIO):
    """A stream that says it is a terminal and keeps what was written."""

    def isatty(self) -> bool:
        return True


def last_line(text: str) -> str:
    """The bar as the terminal shows it last before it is cleared (the last redraw)."""
    frames = [f for f in re.split(r"[\r\n]", text) if "stage" in f]
    return frames[-1] if frames else ""


def test_shown_on_a_terminal_counts_finished_stages():
    term = FakeTerminal()
    p = Progress(3, "run", stream=term)
    assert p.shown
    p.stage("case 1 · lqr")
    assert "0/3" in last_line(term.getvalue())  # the first stage runs, none finished
    assert "case 1 · lqr" in last_line(term.getvalue())
    p.stage("case 1 · smc")
    assert "1/3" in last_line(term.getvalue())
    assert "case 1 · smc" in last_line(term.getvalue())
    p.stage("case 1 · bound")
    p.close()
    assert "3/3" in term.getvalue()
    assert not p.shown
    p.close()  # twice is harmless


@pytest.mark.parametrize("quiet, stream", [(True, FakeTerminal()), (False, io.StringIO())])
def test_silent_with_quiet_or_off_a_terminal(quiet, stream):
    with Progress(2, "run", quiet=quiet, stream=stream) as p:
        assert not p.shown
        p.stage("case 1 · lqr")
        p.stage("case 1 · smc")
    assert stream.getvalue() == ""


def test_closed_on_error():
    term = FakeTerminal()
    with pytest.raises(RuntimeError), Progress(2, "run", stream=term) as p:
        p.stage("case 1")
        raise RuntimeError
    assert not p.shown


@contextlib.contextmanager
def on_terminal():
    """stderr is a terminal inside the block. (Set in the test body: pytest's output
    capture puts its own sys.stderr back after the fixtures have run.)"""
    term, saved = FakeTerminal(), sys.stderr
    sys.stderr = term
    try:
        yield term
    finally:
        sys.stderr = saved


def test_compare_labels_case_policy_and_episode():
    from baselines.policies import LQRPolicy
    from train.compare import compare

    with on_terminal() as terminal:
        rows = compare({"lqr": LQRPolicy()}, cases=(3,), random_seeds=(101, 102), quiet=False)
    out = terminal.getvalue()
    assert "compare" in out
    assert "case 3 · lqr" in out and "case 3 · bound" in out
    assert "case random · lqr · episode 1/2" in out
    assert "case random · bound · episode 2/2" in out
    assert "6/6" in out  # (1 case + 2 episodes) x (lqr + bound)
    assert [r.case for r in rows] == [3, 3, "random", "random"]


def test_evaluate_quiet_writes_nothing():
    from baselines.evaluate import evaluate
    from baselines.policies import PassivePolicy

    with on_terminal() as terminal:
        evaluate({"passive": PassivePolicy()}, cases=(3,), quiet=True)
        assert terminal.getvalue() == ""
        evaluate({"passive": PassivePolicy()}, cases=(3,), quiet=False)
    assert "case 3 · passive" in terminal.getvalue()


def test_off_a_terminal_without_quiet_is_silent(capsys):
    """reproduce and the evaluator, with stderr captured (not a terminal), not quiet."""
    from acld_gym.thesis.cli import main
    from baselines.evaluate import evaluate
    from baselines.policies import PassivePolicy

    assert main(["reproduce", "--t-end", "0.02"]) == 0
    evaluate({"passive": PassivePolicy()}, cases=(3,), quiet=False)
    err = capsys.readouterr().err
    assert "stage" not in err and "reproduce:" not in err and "evaluate:" not in err


def test_reproduce_labels_every_row():
    from acld_gym.thesis.cli import main

    with on_terminal() as terminal:
        assert main(["reproduce", "--t-end", "0.02"]) == 0
    out = terminal.getvalue()
    assert "case 1 · passive · saturated" in out
    assert "case 3 · smc · unsaturated" in out
    assert "18/18" in out


@pytest.mark.parametrize("module", ["baselines.evaluate", "train.compare"])
def test_quiet_flag_reaches_the_evaluator(module, monkeypatch):
    """``--quiet`` on the command line is what the evaluator is called with."""
    import importlib

    mod = importlib.import_module(module)
    seen = {}

    def fake(*args, quiet=True, **kwargs):
        seen["quiet"] = quiet
        raise SystemExit(0)

    name = "evaluate" if module == "baselines.evaluate" else "compare"
    monkeypatch.setattr(mod, name, fake)
    for argv, expected in (([], False), (["--quiet"], True)):
        with pytest.raises(SystemExit):
            mod.main(argv)
        assert seen.pop("quiet") is expected
