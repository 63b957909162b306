"""baselines.evaluation.ise, the thesis-facing view: ISE relative to the thesis LQR on cases
1, 2, 3 and the held-out random loads, and every reference's mean ISE per case."""

import gymnasium as gym
import pytest

import train.core.evaluate as core_evaluate
from baselines.evaluation import ise
from baselines.evaluation.seeds import HELDOUT_SEEDS
from baselines.policies import LQRPolicy, PassivePolicy

EPISODES = ise.eval_episodes(1)


def test_the_episodes_are_the_thesis_cases_and_the_held_out_loads():
    assert ise.eval_episodes() == {1: (0,), 2: (0,), 3: (0,), "random": HELDOUT_SEEDS}
    assert EPISODES["random"] == HELDOUT_SEEDS[:1] and tuple(EPISODES) == ise.CASES
    for name in ("eval_episodes", "rollout_ise", "lqr_ise", "relative_ise", "ise_rel_lqr"):
        assert getattr(core_evaluate, name) is getattr(ise, name), name  # the old path


def test_lqr_is_its_own_yardstick_and_passive_is_worse():
    env = gym.make("ACLDBeam-v1").unwrapped
    rel = ise.ise_rel_lqr(LQRPolicy.for_env(env), "ACLDBeam-v1", EPISODES)
    assert rel == {c: 1.0 for c in EPISODES}  # the same deterministic episodes
    passive = ise.ise_rel_lqr(PassivePolicy.for_env(env), "ACLDBeam-v1", EPISODES)
    assert all(v > 1.0 for v in passive.values())


def test_case_references_hold_each_policy_and_the_bound_per_case():
    env = gym.make("ACLDBeam-v1").unwrapped
    pols = {"passive": PassivePolicy.for_env(env), "lqr": LQRPolicy.for_env(env)}
    refs = ise.case_references("ACLDBeam-v1", EPISODES, bound=True, policies=pols)
    assert refs["env_id"] == "ACLDBeam-v1"
    assert refs["episodes"] == {str(c): list(s) for c, s in EPISODES.items()}
    lqr = ise.lqr_ise("ACLDBeam-v1", EPISODES)
    assert refs["lqr"] == {str(c): v for c, v in lqr.items()}
    for c in EPISODES:
        assert 0 < refs["bound"][str(c)] < min(refs["lqr"][str(c)], refs["passive"][str(c)])
    # JSON's string keys and the cases' own keys both divide
    assert ise.relative_ise(lqr, refs) == pytest.approx({c: 1.0 for c in EPISODES})
    assert ise.relative_ise(lqr, {"lqr": lqr}) == {c: 1.0 for c in EPISODES}


def test_the_lqrs_ise_is_computed_once_per_id_and_episodes(monkeypatch):
    """The yardstick is designed and run once per process for an id and a set of episodes:
    a second call runs no episode and returns an equal dict of its own."""
    first = ise.lqr_ise("ACLDBeam-v1", EPISODES)
    calls = []
    monkeypatch.setattr(ise, "rollout_ise", lambda *a, **k: calls.append(a) or {})
    first[1] = -1.0  # the caller's copy
    again = ise.lqr_ise("ACLDBeam-v1", {c: list(s) for c, s in EPISODES.items()})
    assert not calls and again[1] > 0 and set(again) == set(EPISODES)
    other = ise.lqr_ise("ACLDBeam-v1", {1: (1,)})  # other episodes: computed
    assert calls and other == {}
