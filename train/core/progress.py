"""What a training trial says on the console while it runs: a line per evaluation with
the current validation score (:class:`Progress`), and the retry threshold and every retry
with its reason, which are said whatever ``quiet`` is (a retry is never silent)."""

from __future__ import annotations

import time

__all__ = ["PROGRESS_LOADS", "Progress"]

#: Validation loads of a progress line's score at a learning-curve point (the first of the
#: validation seeds, :func:`train.core.evaluate.validation_seeds`): ~0.1-0.3 s a line,
#: off the training time, as the curve's own evaluations are.
PROGRESS_LOADS = 32


class Progress:
    """The console lines of one trial (picklable: runs in worker processes print their own).

    Parameters
    ----------
    label : str
        What each line starts with (e.g. ``"ppo s0"``).
    quiet : bool
        No line per evaluation; the threshold and the retries are still said.
    loads : int
        Validation loads of the score at a learning-curve point (:data:`PROGRESS_LOADS`).
    """

    def __init__(self, label: str = "", quiet: bool = False, loads: int = PROGRESS_LOADS):
        self.label, self.quiet, self.loads = label, bool(quiet), int(loads)
        self.run, self.runs, self.budget = 0, 1, 0
        self.t0 = time.perf_counter()

    def for_run(self, k: int, runs: int, budget: int) -> Progress:
        """The lines of run ``k`` (from 0) of ``runs``, each of ``budget`` env steps (its
        clock starts at :meth:`start`)."""
        out = Progress(self.label, self.quiet, self.loads)
        out.run, out.runs, out.budget = int(k), int(runs), int(budget)
        return out

    def start(self) -> None:
        """Start the clock of the lines' seconds (a run's start)."""
        self.t0 = time.perf_counter()

    def _prefix(self) -> str:
        run = f" run {self.run + 1}/{self.runs}" if self.runs > 1 else ""
        return f"  [{self.label}{run}]" if self.label or run else " "

    def say(self, text: str) -> None:
        """A line whatever ``quiet`` is (a threshold, a retry)."""
        print(f"{self._prefix()} {text}", flush=True)

    def _line(self, steps: int, text: str) -> None:
        if not self.quiet:
            seconds = time.perf_counter() - self.t0
            self.say(f"{steps:,} / {self.budget:,} env steps, {seconds:.0f} s: {text}")

    def point(self, steps: int, policy, env_id: str) -> None:
        """A learning-curve point: the policy's validation cost on :attr:`loads` loads."""
        if self.quiet:
            return
        from .evaluate import validation_cost, validation_seeds

        cost = validation_cost(policy, env_id, validation_seeds(self.loads))
        self._line(steps, f"validation cost {cost:.4f} ({self.loads} loads)")

    def check(self, steps: int, cost: float, best: float, loads: int) -> None:
        """A checkpoint-selection check: its cost and the best so far, on ``loads`` loads."""
        self._line(steps, f"check: validation cost {cost:.4f}, best {best:.4f} ({loads} loads)")
