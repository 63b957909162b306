"""An agent trained with ``observe_commands`` carries its own commands
(train.commands.CommandMemory in SB3's recurrent ``state``) and so runs on the plain env:
its episode there is the one its actor has on the env that appends the commands; the
exported agent (``metadata.json`` ``commands``) is the SB3 policy, in single and batched
evaluation; a bad state or a bad ``commands`` field is one clear line."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401
from baselines.evaluation.rollout import rollout
from tests.train.tiny_sb3 import tiny_ppo
from train.agent import TrainedAgent
from train.agent_schema import AgentFileError, check_metadata
from train.commands import CommandMemory, command_memory
from train.config import TrainConfig
from train.core import evaluate
from train.core.algos import train_algo
from train.core.sb3_inference import SB3Policy
from train.core.trials import policy_program, save_agent

LAB = "ACLDBeam" + "Lab-v1"


def test_the_memory_is_what_the_env_appends():
    """Driven by the same clipped actions from rest, the memory appended to the plain
    observation is the observation of the env with ``observe_commands``, step by step,
    across an episode's start (the memory at rest again)."""
    kw = dict(load_case="random", actuator_delay=3, obs_mode="measurement")
    plain, wide = gym.make(LAB, **kw), gym.make(LAB, observe_commands=True, **kw)
    memory = command_memory(LAB, dict(kw, observe_commands=True))
    assert memory.as_dict() == {"memory": 3, "observed": 2}
    acts = np.random.default_rng(2).uniform(-300, 300, size=(40, 1))
    state = None
    for episode in range(2):
        p, _ = plain.reset(seed=episode)
        w, _ = wide.reset(seed=episode)
        for k, a in enumerate(acts):
            x, state = memory.observe(p[None], state, np.array([k == 0]))
            np.testing.assert_array_equal(x[0], w)
            state = memory.remember(state, a)
            p, *_ = plain.step(a)
            w, *_ = wide.step(a)


@pytest.mark.parametrize(
    "env_id, kwargs, expected",
    [
        (LAB, {"observe_commands": True}, {"memory": 1, "observed": 1}),
        (LAB, {}, None),
        ("ACLDBeamHard-v1", {"observe_commands": True}, None),  # it observes its command
        ("ACLDBeam-v1", {"observe_commands": True}, None),  # no delay: nothing in flight
    ],
)
def test_a_memory_only_where_the_env_appends_commands(env_id, kwargs, expected):
    memory = command_memory(env_id, kwargs)
    assert (memory and memory.as_dict()) == expected


def test_episode_start_of_another_shape_is_refused_in_one_line():
    memory = CommandMemory(1, 1)
    with pytest.raises(ValueError, match=r"^episode_start: expected 3 flags"):
        memory.observe(np.zeros((3, 9), np.float32), None, np.array([True]))


def test_a_memory_is_checked_against_the_commands_its_env_has_in_flight(lab_agent, tmp_path):
    """An agent whose memory is not its level's delay line (another delay, or a memory on
    a rig without one) is refused at load, naming the field; the one saved is format 3,
    which packages reading formats 1-2 refuse by its number."""
    meta = json.loads((lab_agent / "metadata.json").read_text())
    assert meta["format"] == 3
    for i, (commands, kwargs) in enumerate(
        [
            ({"memory": 3, "observed": 1}, {}),  # a memory longer than the lab rig's delay
            (meta["commands"], {"actuator_delay": 2}),  # trained where two are in flight
            (meta["commands"], {"actuator_delay": 0}),  # a rig without a delay
        ]
    ):
        bad = tmp_path / f"bad-{i}"
        bad.mkdir()
        (bad / "policy.npz").write_bytes((lab_agent / "policy.npz").read_bytes())
        changed = dict(meta, commands=commands, env={"id": LAB, "kwargs": kwargs})
        (bad / "metadata.json").write_text(json.dumps(changed))
        with pytest.raises(AgentFileError, match=r"metadata.json: commands: .* are not the"):
            TrainedAgent.load(bad)


def test_a_state_of_another_shape_is_refused_in_one_line():
    memory = CommandMemory(2, 2)
    with pytest.raises(
        ValueError, match=r"^state: expected the policy's last state, shape \(3, 2\)"
    ):
        memory.observe(np.zeros((3, 9), np.float32), np.zeros((2, 2)), None)
    with pytest.raises(ValueError, match="observed must be at most memory"):
        CommandMemory(1, 2)


@pytest.fixture(scope="module")
def lab_ppo():
    """The PPO recipe on the lab rig, shrunk to 1536 env steps: it observes its commands."""
    cfg = tiny_ppo(restarts=1, restart_above=None, select=None)
    assert cfg.env_kwargs["observe_commands"] is True
    policy, record = train_algo(cfg, 0, LAB, lambda steps, pol: None)
    return cfg, policy, record


def test_the_policy_on_the_plain_env_is_its_actor_on_the_wide_env(lab_ppo):
    _, policy, _ = lab_ppo
    assert policy.commands.as_dict() == {"memory": 1, "observed": 1}
    stateless = SB3Policy(
        policy.model, policy.obs_norm, policy.features, policy.transform, policy.voltage_map
    )
    a = rollout(policy, gym.make(LAB, load_case=1).unwrapped, seed=3)
    b = rollout(stateless, gym.make(LAB, load_case=1, observe_commands=True).unwrapped, seed=3)
    np.testing.assert_allclose(a.voltage, b.voltage, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(a.y, b.y, rtol=1e-6, atol=1e-12)
    assert np.ptp(a.voltage) > 1.0  # it acts: the comparison is not of two silent policies


@pytest.fixture(scope="module")
def lab_agent(lab_ppo, tmp_path_factory):
    """The tiny lab policy saved as an agent folder (train.core.trials.save_agent)."""
    cfg, policy, _ = lab_ppo
    rec = {
        "algo": "ppo", "seed": 0, "name": "ppo", "command": "test", "config": cfg.as_dict(),
        "env_id": LAB, "record": {}, "steps": 1536, "budget": 1536, "train_seconds": 1.0,
        "train_cpu_seconds": 1.0, "final_ise": {}, "curve": [],
    }  # fmt: skip
    return save_agent(policy, rec, tmp_path_factory.mktemp("lab") / "agent")


def test_the_saved_agent_keeps_its_memory(lab_ppo, lab_agent):
    _, policy, _ = lab_ppo
    agent = TrainedAgent.load(lab_agent)
    assert agent.metadata["commands"] == {"memory": 1, "observed": 1}
    assert agent.actor.input_width == 10  # the 9 entries of the lab rig's estimate + 1
    a = rollout(agent, gym.make(LAB, load_case=2).unwrapped, seed=1)
    b = rollout(policy, gym.make(LAB, load_case=2).unwrapped, seed=1)
    np.testing.assert_allclose(a.voltage, b.voltage, rtol=1e-3, atol=1e-2)
    # batched: the validation episodes side by side, the state per sub-env
    seeds = evaluate.validation_seeds(3)
    assert evaluate.validation_cost(agent, LAB, seeds) == pytest.approx(
        evaluate.validation_cost(policy, LAB, seeds), rel=1e-4
    )
    assert policy_program(policy).input_width == 10


def test_score_runs_a_library_policy_on_the_observation_it_was_trained_on(lab_ppo, lab_agent):
    """A policy without a memory, trained with ``observe_commands``, scores on the env that
    appends them (``env_kwargs``) exactly as the agent that remembers them on the plain
    env: the same episodes, the level's references."""
    from train.scoring import score

    _, policy, _ = lab_ppo
    stateless = SB3Policy(
        policy.model, policy.obs_norm, policy.features, policy.transform, policy.voltage_map
    )
    wide = score(stateless, LAB, episodes=2, env_kwargs={"observe_commands": True})
    own = score(TrainedAgent.load(lab_agent), LAB, episodes=2)
    np.testing.assert_allclose(wide.score.scores, own.score.scores, rtol=1e-4, atol=1e-4)
    assert wide.ise_rel_lqr == pytest.approx(own.ise_rel_lqr, rel=1e-3)


@pytest.mark.parametrize(
    "bad",
    [
        {"memory": 0, "observed": 0},
        {"memory": 1, "observed": 0},
        {"memory": 1, "observed": 2},
        {"memory": "1"},
        [1, 1],
    ],
)
def test_a_bad_commands_field_is_refused(bad, lab_agent):
    meta = json.loads((lab_agent / "metadata.json").read_text())
    assert check_metadata(dict(meta)) is not None  # the saved one is well formed
    with pytest.raises(AgentFileError, match=r"metadata.json: commands: expected null or"):
        check_metadata(dict(meta, commands=bad))


def test_the_search_cannot_observe_commands():
    with pytest.raises(ValueError, match="env_kwargs: observe_commands is for the SB3"):
        TrainConfig.from_dict(
            {"algo": "vrs", "timesteps": 1000, "env_kwargs": {"observe_commands": True}}
        )


def test_an_lqr_residual_cannot_observe_commands():
    """The LQR residual reads the env's own observation: refused before any training."""
    data = {"algo": "sac", "timesteps": 1000, "residual": "lqr", "model": {"policy": "MlpPolicy"}}
    with pytest.raises(ValueError, match="observe_commands cannot go with residual"):
        TrainConfig.from_dict({**data, "env_kwargs": {"observe_commands": True}})
