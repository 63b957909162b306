"""baselines.evaluation.seeds: every seed block from one import place, the blocks disjoint,
and the same objects as their data owners'."""

import acld_gym.test_sets as test_sets
import baselines.engineer.tuning as tuning
import train.core.evaluate as core_evaluate
from baselines.evaluation import seeds


def test_the_blocks_are_the_owners_objects():
    for name in ("RESERVED_SEEDS", "HELDOUT_SEEDS", "VALIDATION_SEED0", "TEST_SETS"):
        assert getattr(seeds, name) is getattr(test_sets, name), name
    assert seeds.evaluation_set is test_sets.evaluation_set
    assert seeds.TRAINING_SEEDS is tuning.TRAINING_SEEDS
    for name in ("HELDOUT_SEEDS", "VALIDATION_SEED0", "OBJECTIVE_LOADS", "validation_seeds"):
        assert getattr(core_evaluate, name) is getattr(seeds, name), name
    assert set(seeds.__all__) <= set(dir(seeds))


def test_training_selection_and_test_blocks_are_disjoint():
    test = set().union(*(set(t.seeds) for t in seeds.TEST_SETS.values()))
    selection = set(seeds.HELDOUT_SEEDS) | set(seeds.validation_seeds(seeds.OBJECTIVE_LOADS))
    engineer = set(seeds.TRAINING_SEEDS)
    assert test <= set(seeds.RESERVED_SEEDS)
    assert not test & selection and not test & engineer and not selection & engineer
    for block in (test, selection):  # the random search draws above both (training)
        assert max(block) < seeds.SEARCH_SEEDS.start
    assert seeds.validation_seeds(3) == (
        seeds.VALIDATION_SEED0,
        seeds.VALIDATION_SEED0 + 1,
        seeds.VALIDATION_SEED0 + 2,
    )
