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


def _make_recipe(target: str) -> list[list[str]]:
    """The command lines of a Makefile target (``$(BIN)/`` dropped), split into words."""
    import re
    import shlex

    make = (Path(__file__).resolve().parents[2] / "Makefile").read_text()
    body = re.search(rf"^{target}:.*\n((?:\t.*\n)+)", make, flags=re.M)
    assert body, f"the Makefile has no target {target!r}"
    return [shlex.split(line.strip().replace("$(BIN)/", "")) for line in body[1].splitlines()]


def test_make_agents_retrains_the_repositorys_shipped_agents(tmp_path, monkeypatch):
    """``make agents`` says it retrains the shipped agents: its ship lines replace
    ``train/agents/<name>`` (``--agents train/agents --force``, so a second run replaces them
    too), from the folder its benchmark line writes, and its last line rewrites the
    comparison the agents are tested against; every line parses as its command's."""
    from train.benchmark import build_parser

    lines = _make_recipe("agents")
    from train.compare import build_parser as compare_parser
    from train.ship import build_parser as ship_parser

    bench = [w for w in lines if w[:2] == ["acld-gym", "benchmark"]]
    ships = [w for w in lines if w[:2] == ["acld-gym", "ship"]]
    compares = [w for w in lines if w[:2] == ["acld-gym", "compare"]]
    assert len(bench) == 1 and len(ships) == 3 and len(compares) == 1
    assert lines[-1] == compares[0]  # after the agents it compares are shipped
    out = Path(build_parser().parse_args(bench[0][2:]).out)
    root = Path(__file__).resolve().parents[2]
    assert (root / "train" / "agents").resolve() == AGENTS_DIR.resolve()
    names = []
    for words in ships:
        args = ship_parser().parse_args(words[2:])
        assert Path(args.agents) == Path("train/agents") and args.force
        assert out == Path(args.run) or out in Path(args.run).parents
        names.append(args.name)
    assert sorted(names) == ["ppo", "sac", "vrs"]
    assert all((AGENTS_DIR / n / POLICY_FILE).is_file() for n in names)
    written = compare_parser().parse_args(compares[0][2:])
    assert Path(written.json) == Path("train/agents/compare.json")
    assert Path(written.markdown) == Path("train/agents/compare.md")
    assert written.agents in (None, str(AGENTS_DIR)) or Path(written.agents) == AGENTS_DIR
