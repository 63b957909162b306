"""The sub-mappings of a training config (``distill:``, ``select:``), each validated into
its dataclass by :func:`section`: :class:`SelectConfig` here, the DAgger start's
:class:`train.distill.DistillConfig` in its own module."""

from __future__ import annotations

from dataclasses import MISSING, dataclass, fields

from acld_gym.util.validate import check_int

from .distill import DistillConfig

__all__ = ["SelectConfig", "SECTIONS", "section"]


@dataclass(frozen=True)
class SelectConfig:
    """Checkpoint selection on validation loads (``TrainConfig.select``), as SB3's
    ``EvalCallback`` keeps its best model: every ``every`` env steps from ``start`` on, and
    at the end, the deterministic policy runs ``episodes`` random loads of the validation
    seeds (:func:`train.core.evaluate.validation_seeds`, disjoint from the held-out test
    loads) and is scored by the env's reward per load
    (:func:`train.core.evaluate.validation_cost`: 1 for the passive beam); the run
    returns the best-scoring policy. Its env steps are not counted in the budget (they
    train nothing; the run records them); its time is in the training wall time. The
    learning curve follows the policy being trained (the average, with ``average``), the
    final evaluation is the returned one's.

    Attributes
    ----------
    episodes : int
        Validation episodes per check (random loads), at least 1.
    every : int
        Env steps between checks, at least 1.
    start : int
        Env steps before the first check (0: from the start).
    """

    episodes: int
    every: int
    start: int = 0

    def __post_init__(self):
        check_int("select.episodes", self.episodes, 1, 10**4)
        check_int("select.every", self.every, 1, 10**12)
        check_int("select.start", self.start, 0, 10**12)


#: The sub-mappings of a :class:`train.config.TrainConfig` and the dataclass of each.
SECTIONS = {"distill": DistillConfig, "select": SelectConfig}


def section(cls, data: dict, name: str):
    """The dataclass ``cls`` of a config's mapping ``name`` (``distill``, ``select``);
    ``ValueError`` naming ``name`` and its unknown or missing keys."""
    known = {f.name for f in fields(cls)}
    required = {
        f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING
    }
    unknown, missing = sorted(str(k) for k in set(data) - known), sorted(required - set(data))
    if unknown or missing:
        raise ValueError(
            f"{name}: unknown key(s) {unknown}, missing {missing}; expected some of {sorted(known)}"
        )
    return cls(**data)
