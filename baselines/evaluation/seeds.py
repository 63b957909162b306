"""Every seed block of the benchmark, from one place: what trains, what selects, what tests.

The three uses are disjoint (``tests/test_evaluation_sets.py`` checks it), so a policy is
never scored on an episode it was trained or selected on:

* **training**: SB3 runs seed sub-env i with ``seed + i`` (a few thousand at most); the
  random search (``train.core.search``) draws its episode seeds from :data:`SEARCH_SEEDS`;
  the engineer's designs choose their filter noise models on :data:`TRAINING_SEEDS`
  (:mod:`baselines.engineer.tuning`, their owner);
* **selection**: the thesis cases (seed 0) and the held-out random loads
  :data:`HELDOUT_SEEDS` of the ISE-relative-to-LQR view (:mod:`baselines.evaluation.ise`),
  and the validation loads from :data:`VALIDATION_SEED0` (:func:`validation_seeds`; the
  recipes select their runs on the first :data:`OBJECTIVE_LOADS`);
* **analysis**: the passive episodes of seeds ``0 .. BASIS_SEEDS - 1`` averaged into the
  excitation's unit-pulse response (:mod:`baselines.analysis.control`; noise, not loads);
* **test**: the published test sets :data:`TEST_SETS` in :data:`RESERVED_SEEDS`, the
  episodes of the score (:mod:`baselines.evaluation.score`).

The test sets' data stay in :mod:`acld_gym.test_sets` (a layer under ``baselines``: the
env ids' plain data); this module is their public import place beside the other blocks.
"""

from __future__ import annotations

from acld_gym.test_sets import (
    HELDOUT_SEEDS,
    RESERVED_SEEDS,
    TEST_SEEDS,
    TEST_SETS,
    VALIDATION_SEED0,
    EvaluationSet,
    evaluation_set,
    validation_seeds,
)
from baselines.engineer.tuning import TRAINING_SEEDS

__all__ = [
    "TRAINING_SEEDS",
    "SEARCH_SEEDS",
    "HELDOUT_SEEDS",
    "VALIDATION_SEED0",
    "OBJECTIVE_LOADS",
    "validation_seeds",
    "RESERVED_SEEDS",
    "EvaluationSet",
    "TEST_SETS",
    "TEST_SEEDS",
    "evaluation_set",
    "BASIS_SEEDS",
]

#: The block the random search (``train.core.search``) draws its training episodes' seeds
#: from (it draws below ``2**31 - 10_000_000``).
SEARCH_SEEDS = range(1_000_000, 2**31)

#: Validation loads of a run's selection figure (``validation_cost`` in a trial's record and
#: the report): the 256 the recipes select their runs on (``select: {episodes: 256}`` in
#: ``train/recipes/ppo.yaml`` and ``sac.yaml``).
OBJECTIVE_LOADS = 256

#: Passive episodes (seeds 0 .. 63) averaged into the excitation's unit-pulse response
#: (:class:`baselines.analysis.excitation.PulseSuperposition`, :mod:`baselines.analysis.control`).
BASIS_SEEDS = 64
