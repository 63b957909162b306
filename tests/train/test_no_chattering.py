"""No shipped agent sits at the voltage limit after the beam has settled (case 1, from 0.5 s
after the pulse) more than LQR does (issue 20: no chattering sold as control)."""

from __future__ import annotations

import pytest

from acld_gym.envs.beam_env import ACLDBeamEnv
from baselines.analysis.effort import effort, settled_from
from baselines.evaluate import policies_for, rollout
from train.agent import TrainedAgent
from train.compare import AGENTS_DIR, agent_names


def _settled_limit_fraction(policy) -> float:
    env = ACLDBeamEnv(load_case=1)
    ep = rollout(policy, env, seed=0)
    return effort(ep.voltage, ep.y, env.dt, settled_from(1)).limit_fraction


@pytest.fixture(scope="module")
def lqr_fraction() -> float:
    return _settled_limit_fraction(policies_for(ACLDBeamEnv(load_case=1))["lqr"])


@pytest.mark.parametrize("name", agent_names())
def test_shipped_agent_does_not_sit_at_the_limit(name, lqr_fraction):
    agent = TrainedAgent.load(AGENTS_DIR / name)
    frac = _settled_limit_fraction(agent)
    assert frac <= lqr_fraction + 0.01, (
        f"{name}: at +/-120 V {frac:.0%} of the settled window of case 1 (LQR: {lqr_fraction:.0%})"
    )
