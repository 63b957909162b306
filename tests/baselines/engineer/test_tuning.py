"""The offline search behind the levels' designs."""

import numpy as np

from acld_gym.test_sets import RESERVED_SEEDS, TEST_SETS
from baselines.engineer import DESIGNS, design_kwargs
from baselines.engineer.tuning import RADIUS_MARGIN, TRAINING_SEEDS, grid, search


def test_training_seeds_disjoint_from_every_test_set():
    train = set(TRAINING_SEEDS)
    assert not train & set(RESERVED_SEEDS)
    for test in TEST_SETS.values():
        assert not train & set(test.seeds)


def test_grid_combines_and_drops_none():
    g = grid(model_std=[0.0, 0.1], mode_std=[None, {3: 1.0}])
    assert len(g) == 4
    assert {"model_std": 0.0} in g and {"model_std": 0.1, "mode_std": {3: 1.0}} in g


def test_mode_std_sets_that_modes_states(level_env):
    env = level_env("ACLDBeamHard-v1").unwrapped
    kw = design_kwargs(env.nom, env.config)
    mu = kw["model_std"]
    assert mu.shape == (9,)  # 8 reduced states and the amplifier's
    np.testing.assert_array_equal(mu[4:6], DESIGNS["ACLDBeamHard-v1"]["mode_std"][3])
    assert mu[8] == 0.0 and np.all(mu[:4] == DESIGNS["ACLDBeamHard-v1"]["model_std"])


def test_search_ranks_admissible_designs_first(level_env):
    """A tiny search on Hard: the level's design is admissible on its first training
    plants, and every admissible design ranks above every inadmissible one."""
    env = level_env("ACLDBeamHard-v1", load_case="random")
    ours = DESIGNS["ACLDBeamHard-v1"]
    res = search(env, [ours, {"model_std": 0.1}], n_episodes=2, n_plants=12)
    assert len(res) == 2
    radii = [r[1] for r in res]
    ok = [r <= RADIUS_MARGIN for r in radii]
    assert ok == sorted(ok, reverse=True)
    assert next(r for r in res if r[2] is ours)[1] <= RADIUS_MARGIN
    assert all(np.isfinite(r[0]) for r in res)
