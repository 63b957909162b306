"""``python -m train.compare`` on every level (issue 69): an agents folder of one level is
compared on it (the references, the agents' episodes and the score are that level's, and
the first line says so); ``--env-id`` names a level; an agent of another level than
``--env-id``, agents of different levels in one folder and a bad ``--env-id`` are each
refused in one line, exit status 2, before anything is computed."""

from __future__ import annotations

import contextlib
import io
import json
import shutil

import gymnasium as gym
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import train.compare as cmp
from acld_gym.envs.presets import PRESETS, preset
from baselines.evaluation.rollout import metrics_row, rollout
from train.compare import AGENTS_DIR

LAB = "ACLDBeamLab-v1"


def _folder(tmp_path, **agents) -> str:
    """An agents folder: name -> a shipped agent, ``train/agents/<level>/<algo>``."""
    d = tmp_path / "agents"
    d.mkdir()
    for name, shipped in agents.items():
        shutil.copytree(AGENTS_DIR / shipped, d / name)
    return str(d)


@pytest.fixture
def no_computing(monkeypatch):
    def fail(*args, **kwargs):
        raise AssertionError("computed before the levels were checked")

    for name in ("reference_policies", "compare", "add_scores", "load_agents"):
        monkeypatch.setattr(cmp, name, fail)


def _refused(argv, capsys) -> str:
    with pytest.raises(SystemExit) as e:
        cmp.main(argv)
    out, err = capsys.readouterr()
    assert e.value.code == 2 and "Traceback" not in err and out == ""
    lines = err.strip().splitlines()
    assert lines[-1].startswith("python -m train.compare: error: "), err
    assert not lines[:-1] or lines[0].startswith("usage: ")  # argparse's usage, then one line
    return lines[-1]


def test_a_lab_agent_is_compared_on_its_level(tmp_path, monkeypatch, capsys):
    agents = _folder(tmp_path, my_lab_ppo=f"{LAB}/ppo")
    made = {}

    def few_references(mesh=None, env_id="ACLDBeam-v1"):
        # the command's own references of the level, two of them to keep the test short
        made.update(env_id=env_id, mesh=mesh)
        refs = real(mesh, env_id)
        made["refs"] = refs
        return {k: refs[k] for k in ("passive", "lqg")}

    real = cmp.reference_policies
    monkeypatch.setattr(cmp, "reference_policies", few_references)
    js = tmp_path / "c.json"
    argv = ["--agents", agents, "--score-episodes", "1", "--random-episodes", "1", "--quiet"]
    assert cmp.main([*argv, "--json", str(js)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0] == (
        f"comparing my_lab_ppo with the references on {LAB} (the level the agents were trained on)"
    )
    assert f"Agents vs reference policies on {LAB};" in out
    assert f"score on {LAB}/test-v1 (score v2: 1 random loads" in out
    # the references are the level's: the engineer's designs know its actuator
    assert made["env_id"] == LAB and made["mesh"] == preset(LAB).mesh
    for name in ("lqg", "mpc_rig"):
        config = made["refs"][name].config
        assert config.env_id == LAB and config.actuator_delay == preset(LAB).actuator_delay == 1
    rows = json.loads(js.read_text())
    assert {r["env_id"] for r in rows} == {LAB}
    assert {r["score"]["test_set"] for r in rows if r["score"]} == {f"{LAB}/test-v1"}
    assert {r["policy"] for r in rows} == {"passive", "lqg", "my_lab_ppo", "bound"}
    # the agent's episode of case 1 is the one the level's env gives
    row = next(r for r in rows if r["case"] == 1 and r["policy"] == "my_lab_ppo")
    agent = cmp.load_agents(agents, ["my_lab_ppo"])["my_lab_ppo"]
    ep = rollout(agent, gym.make(LAB, load_case=1), seed=0)
    assert row["ise"] == pytest.approx(metrics_row(1, "x", ep).ise, rel=1e-9)


@pytest.mark.usefixtures("no_computing")
def test_an_agent_of_another_level_than_env_id_is_refused(tmp_path, capsys):
    agents = _folder(tmp_path, my_lab_ppo=f"{LAB}/ppo")
    last = _refused(["--agents", agents, "--env-id", "ACLDBeam-v1", "--quiet"], capsys)
    assert "'my_lab_ppo' was trained on ACLDBeamLab-v1" in last
    assert "--env-id ACLDBeam-v1" in last
    # --only names it: the same
    last = _refused(["--agents", agents, "--only", "my_lab_ppo", "--env-id", "ACLDBeam-v1"], capsys)
    assert "'my_lab_ppo' was trained on ACLDBeamLab-v1" in last


@pytest.mark.usefixtures("no_computing")
def test_agents_of_different_levels_are_refused(tmp_path, capsys):
    agents = _folder(tmp_path, lab=f"{LAB}/ppo", thesis="ACLDBeam-v0/vrs")
    last = _refused(["--agents", agents, "--quiet"], capsys)
    assert "holds agents of different levels" in last
    assert "lab (ACLDBeamLab-v1)" in last and "thesis (ACLDBeam-v0)" in last
    # with --env-id, the one of another level is named (all are checked before computing)
    last = _refused(["--agents", agents, "--env-id", LAB], capsys)
    assert f"'thesis' was trained on ACLDBeam-v0, not on --env-id {LAB}" in last
    assert "'lab'" not in last


def test_the_levels_agents_pass_the_checks(tmp_path, monkeypatch, capsys):
    """The checks refuse nothing that works: --env-id of the agents' level, and --only one
    level's agents of a mixed folder, reach the computing (stubbed), first line said."""
    agents = _folder(tmp_path, lab=f"{LAB}/ppo", thesis="ACLDBeam-v0/vrs")
    seen = []

    def stop(mesh=None, env_id="ACLDBeam-v1"):
        seen.append((env_id, mesh))
        raise AssertionError("computing")

    monkeypatch.setattr(cmp, "reference_policies", stop)
    for argv, level in (
        (["--only", "lab", "--env-id", LAB], LAB),
        (["--only", "thesis"], "ACLDBeam-v0"),
    ):
        with pytest.raises(AssertionError, match="computing"):
            cmp.main(["--agents", agents, "--quiet", *argv])
        first = capsys.readouterr().out.splitlines()[0]
        assert first.startswith(f"comparing {argv[1]} with the references on {level} ")
    assert seen == [(LAB, "converged"), ("ACLDBeam-v0", "thesis")]


@pytest.mark.usefixtures("no_computing")
@pytest.mark.parametrize(
    "value", ["ACLDBeam-v9", "os:system", "acld_gym:ACLDBeam-v1", "", "acldbeam-v1"]
)
def test_a_bad_env_id_is_one_line(value, capsys):
    # ("os:system": Gymnasium's "module:Env" form, never imported)
    last = _refused(["--env-id", value, "--quiet"], capsys)
    assert last.endswith(
        f"--env-id must be one of this package's ids {list(PRESETS)}, got {value!r}"
    )


@settings(max_examples=40, deadline=None)
@given(st.text(max_size=24).filter(lambda v: v not in PRESETS))
@example("ACLDBeam-v1\n")
def test_any_other_env_id_is_refused_in_one_line(value):
    err = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stderr(err):
        for name in ("reference_policies", "compare", "add_scores", "load_agents"):
            mp.setattr(cmp, name, None)  # (never reached)
        with pytest.raises(SystemExit) as e:
            cmp.main([f"--env-id={value}", "--quiet"])
    lines = err.getvalue().strip().splitlines()
    assert e.value.code == 2 and lines[0].startswith("usage: ")
    assert lines[-1] == (
        "python -m train.compare: error: --env-id must be one of this package's ids "
        f"{list(PRESETS)}, got {value!r}"
    )
