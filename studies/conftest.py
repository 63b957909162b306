"""``pytest studies``: the research record's tests, outside the default run (``testpaths``
is ``tests``). Plants built during them are cached in a temporary directory, never in the
user's ~/.cache, removed when the session ends."""

import os
import shutil
import tempfile

import pytest

_CACHE = None
if "ACLD_GYM_CACHE_DIR" not in os.environ:
    _CACHE = tempfile.mkdtemp(prefix="acld-gym-test-cache-")
    os.environ["ACLD_GYM_CACHE_DIR"] = _CACHE


def pytest_sessionfinish(session, exitstatus):
    """Remove the session's plant cache (if this file made it)."""
    if _CACHE is not None:
        shutil.rmtree(_CACHE, ignore_errors=True)


#: Probe tests that no longer run on today's package, by ``module::test``: the probes give
#: ``model.policy`` a policy class, which :class:`train.config.TrainConfig` refuses since
#: commit acbeedc (acld-gym 0.19.3: "model.policy must be a policy's name"). They ran on the
#: versions named in ``studies/README.md``; strict, so one that passes again is reported.
STALE_POLICY_CLASS = {
    "test_actor_steps.py::test_bad_values_are_named",
    "test_actor_steps.py::test_the_law_is_its_own_group_and_the_rest_keeps_the_recipe",
    "test_antithetic.py::test_the_pairs_see_one_load_and_opposite_gain_noise",
    "test_antithetic.py::test_the_probe_is_the_recipe_with_pairs_and_antithetic_noise",
    "test_beta_actor.py::test_the_policy_acts_with_the_beta_and_folding_the_whitening_keeps_its_law",
    "test_critic_first.py::test_a_bad_count_is_named",
    "test_critic_first.py::test_the_actor_waits_for_its_rollouts_while_the_critic_trains",
    "test_episode_noise.py::test_on_the_0_15_recipe_the_draws_come_in_antithetic_pairs",
    "test_episode_noise.py::test_the_draw_is_held_across_rollouts_and_scaled_by_the_current_sigma",
    "test_episode_noise.py::test_the_draw_is_renewed_after_an_episode_of_steps",
    "test_residual_actor.py::test_folding_the_whitening_keeps_the_law_on_the_raw_observation",
    "test_residual_actor.py::test_noise_acts_on_the_whole_latent_or_on_the_linear_gains_alone",
    "test_residual_actor.py::test_on_the_0_15_recipe_the_noise_comes_in_antithetic_pairs",
    "test_residual_actor.py::test_the_mean_is_the_linear_law_plus_a_nonlinear_correction",
    "test_time_critic.py::test_the_critic_vanishes_at_the_end_is_scale_invariant_and_unread_by_the_actor",
}


def pytest_collection_modifyitems(items):
    """Mark :data:`STALE_POLICY_CLASS` as expected to fail (strict)."""
    for item in items:
        key = f"{item.path.name}::{item.originalname}"
        if key in STALE_POLICY_CLASS:
            reason = "stale: the probe passes a policy class; TrainConfig wants a name (acbeedc)"
            item.add_marker(pytest.mark.xfail(strict=True, reason=reason))
