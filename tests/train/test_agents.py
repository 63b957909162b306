"""The shipped agents (train/agents/) and the agent format.

The agents load without executing anything, refuse observations they were not trained
on, act in volts, and reproduce the rows of ``train/agents/compare.json`` -- the table of
``docs/training.md`` and the README's score table, written by
``python -m train.compare --json train/agents/compare.json`` -- on the three thesis cases
and the held-out random set. Tolerance 1e-2 relative on ISE and peak: the evaluation is
deterministic, and the observation is the same on every machine (canonical basis, shipped
plant); the slack covers BLAS round-off in the agents' switching decisions, which a
near-tie can amplify.
"""

from __future__ import annotations

import json
import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest

from acld_gym.envs.beam_env import ACLDBeamEnv
from baselines.evaluate import mean_rows, metrics_row, rollout
from train.agent import META_FILE, POLICY_FILE, AgentFileError, TrainedAgent
from train.compare import AGENTS_DIR, HELDOUT_SEEDS, agent_names, load_agents

RTOL = 1e-2
ROWS = json.loads((AGENTS_DIR / "compare.json").read_text())
#: The page with the comparison tables (``python -m train.compare --markdown``).
PAGE = (Path(__file__).resolve().parents[2] / "docs" / "training.md").read_text()
NAMES = agent_names()


def _row(case, policy):
    return next(r for r in ROWS if r["case"] == case and r["policy"] == policy)


@pytest.fixture(scope="module")
def agents():
    return load_agents()


def test_every_agent_is_in_the_table_with_its_training_label(agents):
    assert len(NAMES) >= 2
    for name, agent in agents.items():
        assert {r["case"] for r in ROWS if r["policy"] == name} == {1, 2, 3, "random"}
        label = _row(1, name)["training"]
        assert label == agent.training
        assert label == (
            "from scratch"
            if agent.metadata["teacher"] is None
            else f"DAgger from {agent.metadata['teacher'].upper()} + RL"
        )


@pytest.mark.parametrize("name", NAMES)
def test_metadata_records_how_it_was_made(agents, name):
    meta = agents[name].metadata
    assert meta["env"]["id"] == "ACLDBeam-v1"
    assert meta["observation"]["env_id"] == "ACLDBeam-v1"
    assert meta["observation"]["basis"] == "modal"
    assert meta["command"].startswith("python -m train")
    assert {"numpy", "gymnasium"} <= set(meta["versions"])


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("case", [1, 2, 3])
def test_thesis_cases_reproduce_the_table(agents, name, case):
    ep = rollout(agents[name], ACLDBeamEnv(load_case=case), seed=0)
    row = metrics_row(case, name, ep)
    ref = _row(case, name)
    assert row.ise == pytest.approx(ref["ise"], rel=RTOL)
    assert row.peak_mm == pytest.approx(ref["peak_mm"], rel=RTOL)
    assert np.abs(ep.voltage).max() <= 120.0
    assert f"{ref['ise']:.3e}" in PAGE


def test_the_pages_show_the_generated_tables():
    """Every row of ``train/agents/compare.md`` (written by ``python -m train.compare``) is
    on the training page, and the README's score table is its score table."""
    root = Path(__file__).resolve().parents[2]
    rows = [
        line
        for line in (AGENTS_DIR / "compare.md").read_text().splitlines()
        if line.startswith("| ")
    ]
    assert rows and [r for r in rows if r not in PAGE.splitlines()] == []
    readme = (root / "README.md").read_text().splitlines()
    scores = rows[rows.index(next(r for r in rows if "score v2 (IQM)" in r)) :]
    assert [r for r in scores if r not in readme] == []


@pytest.mark.parametrize("name", NAMES)
def test_heldout_random_set_reproduces_the_table(agents, name):
    env = ACLDBeamEnv(load_case="random")
    rows = [metrics_row("random", name, rollout(agents[name], env, seed=s)) for s in HELDOUT_SEEDS]
    mean = mean_rows(rows, "random")[0]
    assert mean.ise == pytest.approx(_row("random", name)["ise"], rel=RTOL)


def test_table_is_complete():
    policies = {"passive", "lqr", "smc", "mpc", "mpc_reward", "bound", *NAMES}
    for case in (1, 2, 3, "random"):
        assert {r["policy"] for r in ROWS if r["case"] == case} >= policies
    for r in ROWS:
        assert r["ise_rel_bound"] >= 1.0 - 1e-9 or r["policy"] == "bound"


# --- the format: nothing executes, nothing silently misapplied ----------------------
@pytest.fixture
def agent_dir(tmp_path):
    d = tmp_path / "agent"
    shutil.copytree(AGENTS_DIR / NAMES[0], d)
    return d


class _Bomb:
    """Unpickling this creates a marker file: proof that a pickle was read."""

    marker: Path

    def __reduce__(self):
        return (Path.touch, (self.marker,))


def test_load_never_unpickles(agent_dir, tmp_path):
    marker = tmp_path / "unpickled"
    bomb = _Bomb()
    bomb.marker = marker
    for name in ("vecnormalize.pkl", "model.zip"):
        (agent_dir / name).write_bytes(pickle.dumps(bomb))
    agent = TrainedAgent.load(agent_dir)
    agent.predict(np.zeros(9, np.float32))
    assert not marker.exists()


def test_truncated_policy_file_is_named(agent_dir):
    data = (agent_dir / POLICY_FILE).read_bytes()
    (agent_dir / POLICY_FILE).write_bytes(data[: len(data) // 2])
    with pytest.raises(AgentFileError, match=POLICY_FILE):
        TrainedAgent.load(agent_dir)


def test_bad_metadata_is_named(agent_dir):
    (agent_dir / META_FILE).write_text("{not json")
    with pytest.raises(AgentFileError, match=META_FILE):
        TrainedAgent.load(agent_dir)
    (agent_dir / META_FILE).write_text("[1, 2]")
    with pytest.raises(AgentFileError, match=META_FILE):
        TrainedAgent.load(agent_dir)


def test_action_headroom_is_applied_and_checked(agent_dir):
    """An agent's ``action_headroom`` k (metadata) maps its action a to 120 clip(k a) V,
    as in training; a bad k is refused at load, naming the file."""
    obs = np.random.default_rng(3).normal(size=(64, 9)).astype(np.float32)
    plain = TrainedAgent.load(agent_dir)
    a = plain.actor(obs)[:, 0]
    meta = json.loads((agent_dir / META_FILE).read_text())
    (agent_dir / META_FILE).write_text(json.dumps(dict(meta, action_headroom=2.0)))
    v, _ = TrainedAgent.load(agent_dir).predict(obs)
    assert np.allclose(v[:, 0], np.clip(240.0 * a, -120, 120), atol=1e-4)
    (agent_dir / META_FILE).write_text(json.dumps(dict(meta, action_headroom=0.5)))
    want = rf"{META_FILE}: action_headroom: expected a number in \[1, 100\]"
    with pytest.raises(AgentFileError, match=want):
        TrainedAgent.load(agent_dir)


def _damage(agent_dir: Path, key: str, change) -> None:
    """Rewrite one array of the agent's policy file with ``change(array)``."""
    with np.load(agent_dir / POLICY_FILE) as z:
        arrays = {k: z[k] for k in z.files}
    arrays[key] = change(arrays[key])
    np.savez(agent_dir / POLICY_FILE, **arrays)


@pytest.mark.parametrize("name", NAMES)
def test_every_array_is_checked_against_the_program(name, tmp_path):
    """Wrong shapes (one input too few, a second action, a matrix for a vector) and
    non-finite weights are refused at load, naming the file and the array."""
    cases = [
        ("W0", lambda w: w[:-1], "shape"),
        ("b0", lambda b: np.concatenate([b, b]), "shape"),
        ("b0", lambda b: np.atleast_2d(b), "shape"),
        (
            "W0",
            lambda w: np.where(np.arange(w.size).reshape(w.shape) == 0, np.nan, w),
            "non-finite",
        ),
        ("b0", lambda b: b + np.inf, "non-finite"),
    ]
    for i, (key, change, what) in enumerate(cases):
        d = tmp_path / f"{name}-{i}"
        shutil.copytree(AGENTS_DIR / name, d)
        _damage(d, key, change)
        with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: array '{key}' has {what}"):
            TrainedAgent.load(d, check=False)


def test_fingerprint_mismatch_is_refused_and_says_what_differs(agent_dir):
    meta = json.loads((agent_dir / META_FILE).read_text())
    meta["observation"]["xr_scale"] = [2 * x for x in meta["observation"]["xr_scale"]]
    (agent_dir / META_FILE).write_text(json.dumps(meta))
    with pytest.raises(AgentFileError, match="xr_scale"):
        TrainedAgent.load(agent_dir)
    meta["observation"]["basis"] = "schur"
    (agent_dir / META_FILE).write_text(json.dumps(meta))
    with pytest.raises(AgentFileError, match="basis"):
        TrainedAgent.load(agent_dir)


def test_agent_refuses_an_env_with_another_observation(agents):
    agent = agents[NAMES[0]]
    with pytest.raises(ValueError, match="mesh"):
        rollout(agent, ACLDBeamEnv(mesh="thesis"))
    with pytest.raises(ValueError, match="obs_mode"):
        rollout(agent, ACLDBeamEnv(obs_mode="measurement"))
