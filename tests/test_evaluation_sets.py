"""acld_gym.test_sets: the published test sets are disjoint from every seed used to train or
select the shipped policies, and versioned per env id."""

import itertools
import json

import pytest

import acld_gym
from acld_gym.test_sets import RESERVED_SEEDS, TEST_SEEDS, TEST_SETS, EvaluationSet, evaluation_set
from baselines.evaluation.seeds import (
    HELDOUT_SEEDS,
    OBJECTIVE_LOADS,
    SEARCH_SEEDS,  # the random search's episode seeds (train.core.search)
    validation_seeds,
)
from train.compare import AGENTS_DIR


@pytest.mark.parametrize("env_id", sorted(TEST_SETS))
def test_test_set_is_disjoint_from_training_and_selection(env_id):
    seeds = set(TEST_SEEDS[env_id])
    assert len(seeds) >= 100
    assert not seeds & set(HELDOUT_SEEDS)  # model selection
    assert not seeds & set(validation_seeds(OBJECTIVE_LOADS))  # the recipes' selection
    assert min(seeds) > 10_000  # SB3 sub-env seeds are seed + i, a few thousand at most
    assert max(seeds) < SEARCH_SEEDS.start
    assert seeds <= set(RESERVED_SEEDS)
    assert evaluation_set(env_id).name == f"{env_id}/test-v1"


def test_shipped_agents_were_not_trained_on_the_test_seeds():
    for meta in AGENTS_DIR.glob("*/metadata.json"):
        rec = json.loads(meta.read_text())
        assert rec["seed"] < RESERVED_SEEDS.start, meta


def test_every_env_id_has_a_test_set_and_bad_ids_are_named():
    from acld_gym.envs.presets import PRESETS

    assert acld_gym.ENV_ID in TEST_SETS
    assert set(TEST_SETS) == set(PRESETS)  # every registered id can be scored
    for env_id, test in TEST_SETS.items():
        assert test.env_id == env_id
    with pytest.raises(ValueError, match="ACLDBeam-v9"):
        evaluation_set("ACLDBeam-v9")


def test_each_preset_has_its_own_block_of_seeds():
    """v1 and v0 share their seeds (the same draws on two meshes); a difficulty preset's seeds
    also draw its plant and noise, so each has a block of its own."""
    blocks = {"ACLDBeam-v1": TEST_SEEDS["ACLDBeam-v1"]}
    for env_id in ("ACLDBeamLab-v1", "ACLDBeamHard-v1"):
        blocks[env_id] = TEST_SEEDS[env_id]
    for (a, sa), (b, sb) in itertools.combinations(blocks.items(), 2):
        assert not set(sa) & set(sb), (a, b)
    assert TEST_SEEDS["ACLDBeam-v0"] == TEST_SEEDS["ACLDBeam-v1"]


@pytest.mark.parametrize(
    "seeds, word", [((), "distinct"), ((500_000, 500_000), "distinct"), ((7,), "reserved")]
)
def test_a_set_outside_the_rules_is_refused(seeds, word):
    with pytest.raises(ValueError, match=word):
        EvaluationSet("ACLDBeam-v1", 1, seeds)


def test_first_n_is_a_prefix():
    full = evaluation_set(acld_gym.ENV_ID)
    assert full.first(3).seeds == full.seeds[:3]
    with pytest.raises(ValueError, match="n must be"):
        full.first(0)
