"""The agents shipped per level (``train/agents/<env id>/<algo>/``, issue 67): each is
labelled with its level and how it was trained, acts in volts within the limit on its own
level, does not chatter at the limit once the beam has settled on the thesis cases, and is
refused on another level's env (its observation fingerprint)."""

import gymnasium as gym
import numpy as np
import pytest

from acld_gym.envs.presets import PRESETS
from acld_gym.physics.actuator import V_LIMIT
from baselines.analysis.effort import settled_from
from baselines.evaluation.rollout import rollout
from train.agent import TrainedAgent
from train.agent_dirs import agent_names
from train.compare import AGENTS_DIR

LEVEL_DIRS = sorted(p for p in AGENTS_DIR.iterdir() if p.is_dir() and p.name in PRESETS)
AGENT_DIRS = [a for level in LEVEL_DIRS for a in sorted(level.iterdir()) if a.is_dir()]


def test_every_rig_level_ships_agents():
    levels = {p.name for p in LEVEL_DIRS}
    assert {"ACLDBeamLab-v1", "ACLDBeamHard-v1"} <= levels
    for level in LEVEL_DIRS:
        assert "ppo" in {a.name for a in level.iterdir()}, level.name


def test_level_folders_are_not_agents_of_v1():
    """train.compare reads train/agents/<name>/ only: a level's folder is not one."""
    names = agent_names(AGENTS_DIR)
    assert not set(names) & {p.name for p in LEVEL_DIRS}


@pytest.mark.parametrize("path", AGENT_DIRS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_agent_is_labelled_and_acts_on_its_own_level(path):
    agent = TrainedAgent.load(path)
    meta = agent.metadata
    assert meta["env"]["id"] == path.parent.name
    assert meta["algo"] == path.name and agent.training == "from scratch"
    assert meta["benchmark"] or meta["config"]  # how it was trained: the recipe it ran
    assert meta["command"].startswith("python -m train")
    env = gym.make(path.parent.name, load_case=1)
    ep = rollout(agent, env, seed=0)
    assert np.all(np.abs(ep.voltage) <= V_LIMIT * (1 + 1e-12))  # the amplifier: rounding
    # after the tip has settled, the voltage is not pinned at the limit
    after = ep.voltage[ep.t >= settled_from(1)]
    assert after.size and np.mean(np.abs(after) >= 0.999 * V_LIMIT) < 0.05


@pytest.mark.parametrize("path", AGENT_DIRS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_agent_is_refused_on_another_level(path):
    agent = TrainedAgent.load(path)
    other = next(i for i in ("ACLDBeamHard-v1", "ACLDBeam-v0") if i != path.parent.name)
    with pytest.raises(ValueError):
        rollout(agent, gym.make(other, load_case=1), seed=0)
