"""The benchmark's evaluators agree with each other: the side-by-side batched ISE is the
single-env rollouts' ISE (one episode per seed, the same loads), and the validation rollout
counts every step of every episode."""

import json

import gymnasium as gym
import numpy as np
import pytest

from baselines.policies import LQRPolicy
from train.core import evaluate

EPISODES = {1: (0,), 3: (0,), "random": (100000, 100001, 100002)}


@pytest.fixture(scope="module")
def lqr():
    return LQRPolicy.for_env(gym.make("ACLDBeam-v1").unwrapped)


def test_batched_ise_is_the_single_env_ise(lqr):
    batched = evaluate.batched_ise(lqr, "ACLDBeam-v1", EPISODES)
    single = evaluate.rollout_ise(lqr, "ACLDBeam-v1", EPISODES)
    assert batched.keys() == single.keys() == EPISODES.keys()
    for case in EPISODES:
        assert batched[case] > 0
        assert batched[case] == pytest.approx(single[case], rel=1e-9), case


class _Push:
    """A constant 120 V, whatever the observation."""

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(obs)
        return np.full(obs.shape[:-1] + (1,), 120.0, dtype=np.float32), state


def test_validation_rollout_counts_each_episode_until_it_ends():
    cost, steps = evaluate.validation_rollout(_Push(), "ACLDBeam-v1", seeds=(200000, 200001))
    env = gym.make("ACLDBeam-v1").unwrapped
    assert steps == 2 * env.config.max_steps  # no early end at the default 20 mm limit
    assert np.isfinite(cost) and cost > 1.0  # a constant 120 V is worse than no control


def test_references_are_one_record_of_the_one_cache(tmp_path, monkeypatch, capsys):
    """train.core.evaluate.references is a record of baselines.evaluation.cache: computed
    once, read back while its inputs hold, and a file of the old format (no format, kind or
    key) is one line on stderr, then recomputed and replaced."""
    from baselines.evaluation.cache import FORMAT
    from train.core.records import check_references

    calls = []

    def fake_case_references(env_id, episodes, bound, policies):
        calls.append(env_id)
        data = {"env_id": env_id, "episodes": {str(c): list(s) for c, s in episodes.items()}}
        for k, name in enumerate(("passive", "lqr", "smc", "mpc", "bound")):
            data[name] = {str(c): 1.0 / (k + 1) for c in episodes}
        return data

    monkeypatch.setattr(evaluate, "case_references", fake_case_references)
    monkeypatch.setattr(evaluate, "validation_cost", lambda *a, **k: 0.5)
    path = tmp_path / "references-ACLDBeam-v1.json"
    refs = evaluate.references("ACLDBeam-v1", path, 2)
    assert refs["format"] == FORMAT and refs["kind"] == evaluate.REFERENCES_KIND
    assert check_references(refs, path) is refs and refs["validation_cost"]["smc"] == 0.5
    assert json.loads(path.read_text()) == refs and len(calls) == 1
    assert evaluate.references("ACLDBeam-v1", path, 2) == refs and len(calls) == 1  # reused
    old = {k: v for k, v in refs.items() if k not in ("format", "kind", "key")}
    path.write_text(json.dumps(old))
    capsys.readouterr()
    assert evaluate.references("ACLDBeam-v1", path, 2) == refs and len(calls) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "another format" in err[0] and str(path) in err[0]
    assert json.loads(path.read_text()) == refs  # replaced
    other = evaluate.references("ACLDBeam-v1", path, 3)  # other episodes: another key
    assert other["key"] != refs["key"] and len(calls) == 3
    assert evaluate.references("ACLDBeam-v1", None, 2) == refs and len(calls) == 4
