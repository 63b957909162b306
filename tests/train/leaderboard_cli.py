"""What the tests of ``python -m train.leaderboard`` share: the command run in-process as a
user runs it (:func:`run`)."""

from __future__ import annotations

from acld_gym.util.validate import run_main
from train.leaderboard.cli import main

PROG = "python -m train.leaderboard"


def run(argv, capsys) -> tuple[int, str, str]:
    """``(exit code, stdout, stderr)`` of ``main(argv)`` as the command runs it
    (:func:`acld_gym.util.validate.run_main`: one line per bad file; argparse's usage errors
    exit 2)."""
    try:
        code = run_main(lambda: main([str(a) for a in argv]), PROG)
    except SystemExit as exc:
        code = exc.code
    out = capsys.readouterr()
    return code, out.out, out.err
