"""The shipped agents (train/agents/): they load, act in volts, and reproduce the
numbers of ``train/agents/compare.json`` -- the table in the README, written by
``python -m train.compare --json train/agents/compare.json`` -- on the three
thesis cases and the held-out random set. Tolerance: 1e-2 relative on ISE and peak
(deterministic evaluation; the slack covers floating-point differences of
torch/BLAS between machines)."""

import json
from pathlib import Path

import numpy as np
import pytest

from acld_gym.env import ACLDBeamEnv
from baselines.evaluate import mean_rows, metrics_row, rollout
from train.compare import AGENTS_DIR, HELDOUT_SEEDS, load_agents

RTOL = 1e-2
ROWS = json.loads((AGENTS_DIR / "compare.json").read_text())
README = (Path(__file__).resolve().parents[1] / "README.md").read_text()


def _row(case, policy):
    return next(r for r in ROWS if r["case"] == case and r["policy"] == policy)


@pytest.fixture(scope="module")
def agents():
    return load_agents()


@pytest.mark.parametrize("name", ["ppo", "sac"])
def test_metadata_records_how_it_was_made(agents, name):
    meta = agents[name].metadata
    assert meta["algo"] == name and meta["config"]["load_case"] == "random"
    assert meta["command"].startswith(f"python -m train {name}")
    assert {"torch", "stable_baselines3", "gymnasium"} <= set(meta["versions"])
    # initialised by DAgger from the MPC, then trained; the shipped checkpoint's step
    assert meta["config"]["distill"]["teacher"] == "mpc"
    assert meta["distill"]["history"][-1]["agreement"] > 0.9
    assert 0 <= meta["best_timesteps"] <= meta["timesteps"]


@pytest.mark.parametrize("name", ["ppo", "sac"])
@pytest.mark.parametrize("case", [1, 2, 3])
def test_thesis_cases_reproduce_the_table(agents, name, case):
    ep = rollout(agents[name], ACLDBeamEnv(load_case=case), seed=0)
    row = metrics_row(case, name, ep)
    ref = _row(case, name)
    assert row.ise == pytest.approx(ref["ise"], rel=RTOL)
    assert row.peak_mm == pytest.approx(ref["peak_mm"], rel=RTOL)
    assert np.abs(ep.voltage).max() <= 120.0
    assert f"{ref['ise']:.3e}" in README


@pytest.mark.parametrize("name", ["ppo", "sac"])
def test_heldout_random_set_reproduces_the_table(agents, name):
    env = ACLDBeamEnv(load_case="random")
    rows = [metrics_row("random", name, rollout(agents[name], env, seed=s))
            for s in HELDOUT_SEEDS]
    mean = mean_rows(rows, "random")[0]
    assert mean.ise == pytest.approx(_row("random", name)["ise"], rel=RTOL)


def test_table_is_complete():
    policies = {"passive", "lqr", "smc", "mpc", "ppo", "sac", "bound"}
    for case in (1, 2, 3, "random"):
        assert {r["policy"] for r in ROWS if r["case"] == case} >= policies
    for r in ROWS:
        assert r["ise_rel_bound"] >= 1.0 - 1e-9 or r["policy"] == "bound"


ROBUST = json.loads((AGENTS_DIR / "compare_param_noise.json").read_text())


@pytest.mark.parametrize("name", ["ppo_robust", "sac_robust"])
def test_robust_agents_reproduce_the_randomized_table(name):
    """Trained with param_noise 0.1; case 1 on the seed-0 randomized plant as in the
    README's robustness table."""
    agent = load_agents(names=(name,))[name]
    assert agent.metadata["config"]["param_noise"] == 0.1
    ep = rollout(agent, ACLDBeamEnv(load_case=1, param_noise=0.1), seed=0)
    ref = next(r for r in ROBUST if r["case"] == 1 and r["policy"] == name)
    assert metrics_row(1, name, ep).ise == pytest.approx(ref["ise"], rel=RTOL)
    assert f"{ref['ise']:.3e}" in README


@pytest.mark.parametrize("name", ["ppo", "sac", "ppo_robust", "sac_robust"])
def test_numpy_actor_equals_sb3_predict(name):
    agent = load_agents(names=(name,))[name]
    obs = np.random.default_rng(0).normal(0.0, 2.0, (256, 7)).astype(np.float32)
    norm = agent.obs_norm.normalize_obs(obs)
    sb3, _ = agent.model.predict(norm, deterministic=True)
    # equal up to torch's float32 rounding, which scales with the weights (the
    # distilled linear actors have |w|_1 of several thousand: a thin boundary layer)
    scale = max(np.abs(op[1]).sum(axis=0).max() for op in agent.actor.ops if op[0] == "linear")
    atol = 1e-5 + 4 * np.finfo(np.float32).eps * scale
    assert np.allclose(agent.actor(norm), sb3, rtol=0.0, atol=atol)
    v, _ = agent.predict(obs)
    assert v.shape == (256, 1) and np.all(np.abs(v) <= 120.0)
    with pytest.raises(ValueError, match="deterministic"):
        agent.predict(obs[0], deterministic=False)
