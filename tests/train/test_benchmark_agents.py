"""The benchmark's trained policies as safe agent directories: the exported actor program
acts exactly like the trained policy, the metadata says "from scratch" with no teacher,
and ``train.ship`` / ``train.compare`` pick the agent up."""

import json

import gymnasium as gym
import numpy as np
import pytest
import yaml

import acld_gym  # noqa: F401  (registers the env ids)
from acld_gym.wrappers import whitening
from train.agent import TrainedAgent, linear_program
from train.core.search import LinearDirectionActor


def _observations(n=64, seed=0):
    """Observations of a passive episode (so of the env's scale and correlations)."""
    env = gym.make("ACLDBeam-v1", load_case="random").unwrapped
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for _ in range(n - 1):
        obs, *_ = env.step(np.zeros(1, np.float32))
        out.append(obs)
    return np.array(out)


@pytest.mark.parametrize("features", [None, "direction"])
@pytest.mark.parametrize("whiten", [False, True])
def test_linear_program_acts_like_the_random_search_actor(features, whiten):
    z = _observations()
    rng = np.random.default_rng(1)
    transform = whitening(z / np.linalg.norm(z, axis=1, keepdims=True)) if whiten else None
    dim = z.shape[1] + 1 + (features == "direction")
    actor = LinearDirectionActor(rng.normal(0, 3.0, dim), 120.0, features, transform)
    agent = TrainedAgent(linear_program(actor.theta, transform, features), {}, "vrs")
    v_actor, _ = actor.predict(z)
    v_agent, _ = agent.predict(z)
    assert np.abs(v_actor).max() == pytest.approx(120.0)  # the clip is exercised
    np.testing.assert_allclose(v_agent, v_actor, rtol=1e-5, atol=1e-4)


def test_linear_program_rejects_unknown_features():
    with pytest.raises(ValueError, match="features"):
        linear_program(np.zeros(3), None, "quadratic")


def test_benchmark_saves_shippable_agents(tmp_path, capsys):
    from train.benchmark import agent_dir, main
    from train.compare import agent_names
    from train.ship import ship

    vrs = yaml.safe_load(open("train/recipes/vrs.yaml"))
    vrs.update(timesteps=8000, loads={"random": 1}, eval_points=1)
    vrs["model"] = {**vrs["model"], "n_directions": 2, "top_directions": 1}
    ppo = yaml.safe_load(open("train/recipes/ppo.yaml"))
    ppo.update(timesteps=1024, n_envs=2, eval_points=1, whiten_steps=256)  # the recipe's
    # whitening, folded into the exported actor
    ppo["model"] = {**ppo["model"], "n_steps": 256, "batch_size": 256, "n_epochs": 1}
    configs = []
    for name, data in (("tiny_vrs", vrs), ("tiny_ppo", ppo)):
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(data))
        configs.append(str(tmp_path / f"{name}.yaml"))
    out = tmp_path / "bench"
    assert (
        main(
            [
                "--config",
                *configs,
                "--seeds",
                "0",
                "--backend",
                "local",
                "--random-episodes",
                "1",
                "--no-bound",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    capsys.readouterr()
    trials = {
        n: json.loads((out / "trials" / f"{n}-s0.json").read_text())
        for n in ("tiny_vrs", "tiny_ppo")
    }
    for name, rec in trials.items():
        d = agent_dir(out, name, 0)
        agent = TrainedAgent.load(d)  # fingerprint checked against ACLDBeam-v1 today
        assert agent.training == "from scratch" and agent.metadata["teacher"] is None
        assert agent.metadata["command"].startswith(f"python -m train.benchmark --config {name}")
        assert not list(d.glob("*.pkl")) and not list(d.glob("*.zip"))
        # the saved agent reproduces the trial's own final evaluation (case 1, seed 0)
        from acld_gym.envs.beam_env import ACLDBeamEnv
        from baselines.evaluate import metrics_row, rollout

        ise = metrics_row(1, name, rollout(agent, ACLDBeamEnv(load_case=1), seed=0)).ise
        assert ise == pytest.approx(rec["final_ise"]["1"], rel=1e-5)
    shipped = ship(agent_dir(out, "tiny_vrs", 0), "vrs_tiny", tmp_path / "agents")
    assert (shipped / "learning_curve.csv").is_file()
    assert agent_names(tmp_path / "agents") == ["vrs_tiny"]
