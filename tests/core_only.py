"""Runs Python code in a subprocess as a core install (no extras) would: the extras'
imports are blocked. Shared by the light-install and core-install tests."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

#: Top-level packages that only the extras bring (and tqdm, which the env does not need).
BLOCKED = ("torch", "stable_baselines3", "sb3_contrib", "osqp", "tensorboard", "yaml", "ray")

_BLOCKER = f"""
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in {BLOCKED!r}:
            raise ImportError(f'blocked: {{name}} (not in a core install)')
sys.meta_path.insert(0, Block())
"""


def run_core_only(
    code: str, cwd: str | Path | None = None, blocked_extra: tuple[str, ...] = ()
) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter with :data:`BLOCKED` (and ``blocked_extra``)
    unimportable; the completed process, its output captured as text."""
    blocker = _BLOCKER.replace(repr(BLOCKED), repr(BLOCKED + tuple(blocked_extra)))
    return subprocess.run(
        [sys.executable, "-c", blocker + code], capture_output=True, text=True, cwd=cwd
    )
