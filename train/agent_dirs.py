"""The agents in a folder: :data:`AGENTS_DIR` (the shipped agents, ``train/agents/``),
:func:`agent_names` (those trained on a mesh) and :func:`load_agents` (them as policies).
Read by ``python -m train.compare``, the figures and the tests; re-exported by
:mod:`train.compare`."""

from __future__ import annotations

from pathlib import Path

from acld_gym.envs.presets import PRESETS

from .agent import META_FILE, AgentFileError, TrainedAgent
from .agent_files import read_metadata

__all__ = ["AGENTS_DIR", "agent_mesh", "agent_folders", "agent_names", "load_agents"]

#: The shipped agents (package data).
AGENTS_DIR = Path(__file__).resolve().parent / "agents"


def agent_mesh(env: dict) -> str:
    """The truth mesh an agent was trained on, from its metadata's ``env`` record: its
    ``mesh`` keyword, else its level's (:data:`acld_gym.envs.presets.PRESETS`)."""
    return env.get("kwargs", {}).get("mesh", PRESETS[env["id"]].get("mesh", "converged"))


def agent_folders(directory: str | Path = AGENTS_DIR) -> list[tuple[str, dict | None]]:
    """``(name, env record)`` of every agent directory under ``directory`` (sorted), the
    record None where the metadata does not read (:func:`train.agent_files.read_metadata`):
    loading that agent names the fault, it is never skipped in silence."""
    out = []
    for d in sorted(Path(directory).iterdir()) if Path(directory).is_dir() else []:
        if (d / META_FILE).exists() or (d / META_FILE).is_symlink():
            try:
                out.append((d.name, read_metadata(d)["env"]))
            except (AgentFileError, OSError):
                out.append((d.name, None))  # TrainedAgent.load reports it
    return out


def agent_names(directory: str | Path = AGENTS_DIR, mesh: str = "converged") -> list[str]:
    """The agent directories under ``directory`` trained on ``mesh`` (sorted), and each
    whose metadata does not read (:func:`agent_folders`)."""
    return [n for n, env in agent_folders(directory) if env is None or agent_mesh(env) == mesh]


def load_agents(directory: str | Path = AGENTS_DIR, names=None, mesh: str = "converged") -> dict:
    """The agents ``directory/<name>/`` as policies (default: every agent trained on
    ``mesh``); ``FileNotFoundError`` / :class:`train.agent.AgentFileError` if one is
    missing or does not match its env."""
    directory = Path(directory)
    names = agent_names(directory, mesh) if names is None else names
    return {name: TrainedAgent.load(directory / name, name) for name in names}
