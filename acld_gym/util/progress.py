"""A progress line for long commands: one bar on the terminal, silent otherwise.

``make run``, ``python -m baselines.evaluate``, ``python -m train.compare`` and
``acld-gym reproduce`` report each stage ("case random · mpc · episode 3/20") on one line of
stderr, only when stderr is a terminal and ``--quiet`` was not given, so logs and pipes
stay clean. The count is of stages finished; the label is the stage running now.
"""

from __future__ import annotations

import sys
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """``tqdm`` over ``total`` stages, labelled with the stage that runs; a no-op when not
    shown.

    Parameters
    ----------
    total : int
        Number of stages (calls of :meth:`stage`).
    desc : str
        The bar's name (the command).
    quiet : bool
        Never show the bar.
    stream : file, optional
        Where the bar goes; ``sys.stderr`` by default. Shown only if ``stream.isatty()``.
    """

    def __init__(
        self, total: int, desc: str = "", quiet: bool = False, stream: TextIO | None = None
    ):
        stream = sys.stderr if stream is None else stream
        self._bar = None
        self._running = False
        if not quiet and stream.isatty():
            from tqdm import tqdm  # only on a terminal: a core env runs without it

            self._bar = tqdm(
                total=total, desc=desc, unit="stage", file=stream, leave=False, dynamic_ncols=True
            )

    @property
    def shown(self) -> bool:
        """Whether the bar is on the terminal."""
        return self._bar is not None

    def stage(self, label: str) -> None:
        """Stage ``label`` starts: the one before it (if any) counts as finished."""
        if self._bar is not None:
            if self._running:
                self._bar.update(1)
            self._bar.set_postfix_str(label)  # redraws now, whatever tqdm's interval
            self._running = True

    def close(self) -> None:
        """The running stage is finished; the bar leaves the terminal."""
        if self._bar is not None:
            if self._running:
                self._bar.update(1)
                self._bar.refresh()  # the last count shows before the bar is cleared
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
