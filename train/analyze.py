"""``python -m train.analyze POLICY [POLICY ...] [--env-id ID] ...``: the command of
:mod:`baselines.analyze` with train's agent loader, so that a POLICY may be an agent
directory (``train/agents/ppo``, ``agents/my_vrs``, a benchmark's ``agents/ppo-s0``) as well
as a reference's name. The options and the output are :mod:`baselines.analyze`'s; the agent
is read as :meth:`train.agent.TrainedAgent.load` reads it (data only, checked, its
observation fingerprint against the level's), named after its folder.

baselines sits under train and imports nothing from it; this module is where the two meet.
"""

from __future__ import annotations

import sys
from pathlib import Path

from acld_gym.util.text import invoked_as, prog
from acld_gym.util.validate import run_main
from baselines import analyze as _analyze
from train.agent import TrainedAgent

__all__ = ["load_agent", "main"]


def load_agent(path: Path) -> TrainedAgent:
    """The agent in the directory ``path``, named after it."""
    return TrainedAgent.load(path, path.name)


def main(argv: list[str] | None = None) -> int:
    """The command: ``argv`` as on the command line (:func:`baselines.analyze.main`), its
    usage and errors under this command's name."""
    with invoked_as(prog("python -m train.analyze")):
        return _analyze.main(argv, load_agent=load_agent)


if __name__ == "__main__":
    sys.exit(run_main(main))
