"""A progress line for long commands: one bar on the terminal, silent otherwise.

``make run``, ``python -m baselines.evaluate``, ``python -m train.compare`` and
``acld-gym reproduce`` report each stage ("case 2 · mpc · episode 3/20") on one line of
stderr, only when stderr is a terminal and ``--quiet`` was not given, so logs and pipes
stay clean.
"""

from __future__ import annotations

import sys

__all__ = ["Progress"]


class Progress:
    """``tqdm`` over ``total`` stages with a label per stage; a no-op when not shown."""

    def __init__(self, total: int, desc: str = "", quiet: bool = False):
        self._bar = None
        if not quiet and sys.stderr.isatty():
            from tqdm import tqdm

            self._bar = tqdm(total=total, desc=desc, unit="stage", file=sys.stderr,
                             leave=False, dynamic_ncols=True)

    def stage(self, label: str) -> None:
        """Show ``label`` and count one stage done."""
        if self._bar is not None:
            self._bar.set_postfix_str(label, refresh=False)
            self._bar.update(1)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
