"""``python -m train.ship`` ships into ``./agents`` of the current directory (or ``--agents
DIR``), never into the installed package's ``train/agents/``."""

from __future__ import annotations

from pathlib import Path

import pytest

from train.agent import POLICY_FILE, TrainedAgent
from train.compare import AGENTS_DIR
from train.ship import main, ship


def _tree(root):
    """Every file under ``root`` with its bytes and every folder (relative paths)."""
    return {
        str(p.relative_to(root)): p.read_bytes() if p.is_file() else None
        for p in sorted(root.rglob("*"))
        if "__pycache__" not in p.parts
    }


def test_ship_without_agents_writes_into_the_working_directory(tmp_path, monkeypatch, capsys):
    before = _tree(AGENTS_DIR)
    monkeypatch.chdir(tmp_path)
    assert main([str(AGENTS_DIR / "vrs"), "mine"]) == 0
    shipped = tmp_path / "agents" / "mine"
    said = capsys.readouterr().out.strip()
    assert said.startswith("shipped ") and said.endswith("/")
    assert Path(said[len("shipped ") : -1]).resolve() == shipped.resolve()
    assert (shipped / POLICY_FILE).read_bytes() == (AGENTS_DIR / "vrs" / POLICY_FILE).read_bytes()
    assert TrainedAgent.load(shipped).metadata["algo"] == "vrs"
    assert [p.name for p in (tmp_path / "agents").iterdir()] == ["mine"]
    assert not (AGENTS_DIR / "mine").exists()
    # --force semantics are kept: a name is replaced only with --force
    with pytest.raises(SystemExit) as exit_:
        main([str(AGENTS_DIR / "sac"), "mine"])
    assert exit_.value.code == 2
    assert "pass --force" in capsys.readouterr().err.splitlines()[-1]
    assert TrainedAgent.load(shipped).metadata["algo"] == "vrs"
    assert main([str(AGENTS_DIR / "sac"), "mine", "--force"]) == 0
    assert TrainedAgent.load(shipped).metadata["algo"] == "sac"
    assert _tree(AGENTS_DIR) == before  # the package's agents, byte for byte


def test_agents_dir_overrides_and_the_function_default_is_the_working_directory(
    tmp_path, monkeypatch
):
    before = _tree(AGENTS_DIR)
    monkeypatch.chdir(tmp_path)
    assert main([str(AGENTS_DIR / "ppo"), "mine", "--agents", "elsewhere/agents"]) == 0
    assert TrainedAgent.load(tmp_path / "elsewhere/agents/mine").metadata["algo"] == "ppo"
    assert not (tmp_path / "agents").exists()
    assert ship(AGENTS_DIR / "ppo", "other").resolve() == (tmp_path / "agents/other").resolve()
    assert TrainedAgent.load(tmp_path / "agents" / "other").metadata["algo"] == "ppo"
    assert _tree(AGENTS_DIR) == before
