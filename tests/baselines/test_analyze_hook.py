"""baselines.analyze reads agent directories through a loader hook (``load_agent``): the
library and the command take any object with ``predict``, and only the default loader
reaches up to train (the layer above)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from baselines.analyze import load_trained_agent, main, resolve_policies, resolve_policy
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


def test_the_default_loader_reads_a_shipped_agent():
    agent = ROOT / "tests" / "data" / "agents" / "ppo_dagger"
    policy = load_trained_agent(agent)
    assert policy.name == "ppo_dagger" and callable(policy.predict)


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
