"""baselines.analyze reads agent directories through a loader hook (``load_agent``): the
library and the command take any object with ``predict``; without a loader an agent
directory is refused in one line naming ``python -m train.analyze``, which passes train's
loader (train is the layer above: baselines imports nothing from it)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from baselines.analyze import main, resolve_policies, resolve_policy
from baselines.policies import LQRPolicy

ROOT = Path(__file__).resolve().parents[2]


def test_a_directory_is_read_by_the_loader_passed(tmp_path):
    seen = []
    policy = LQRPolicy()

    def loader(path):
        seen.append(path)
        return policy

    agent = tmp_path / "my_agent"
    agent.mkdir()
    assert resolve_policies(str(agent), "ACLDBeam-v1", load_agent=loader) == [(policy, "my_agent")]
    assert resolve_policy(str(agent), "ACLDBeam-v1", load_agent=loader) == (policy, "my_agent")
    assert seen == [agent, agent]


def test_main_hands_its_loader_on_and_reports_its_refusal(tmp_path, capsys):
    def refuse(path):
        raise ValueError(f"POLICY: {path.name} is not an agent this loader reads")

    agent = tmp_path / "other"
    agent.mkdir()
    with pytest.raises(SystemExit) as e:
        main([str(agent), "--score-episodes", "0", "--quiet"], load_agent=refuse)
    assert e.value.code == 2
    assert "POLICY: other is not an agent this loader reads" in capsys.readouterr().err


def test_without_a_loader_an_agent_directory_is_one_line_naming_train_analyze(capsys):
    agent = ROOT / "tests" / "data" / "agents" / "ppo_dagger"
    with pytest.raises(ValueError, match="python -m train.analyze"):
        resolve_policies(str(agent), "ACLDBeam-v1")
    with pytest.raises(SystemExit) as e:
        main([str(agent), "--score-episodes", "0", "--quiet"])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "is an agent directory" in err[-1] and "Traceback" not in "".join(err)


def test_train_analyze_reads_a_shipped_agent(capsys):
    from train.analyze import load_agent
    from train.analyze import main as train_main

    agent = ROOT / "tests" / "data" / "agents" / "ppo_dagger"
    policy = load_agent(agent)
    assert policy.name == "ppo_dagger" and callable(policy.predict)
    with pytest.raises(SystemExit) as e:
        train_main([str(agent), "--env-id", "ACLDBeam-v9", "--quiet"])
    assert e.value.code == 2
    assert "python -m train.analyze: error: --env-id" in capsys.readouterr().err


def test_references_and_the_command_import_nothing_from_train():
    code = (
        "import sys\n"
        "from baselines.analyze import resolve_policies\n"
        "resolve_policies('lqr', 'ACLDBeam-v1')\n"
        "print(sorted(m for m in sys.modules if m == 'train' or m.startswith('train.')))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
