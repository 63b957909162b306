"""The level of ``python -m train.compare``: which registered id the agents, the references,
the scores and every table are on, settled from the arguments and the agents' metadata
before anything is computed.

``--env-id ID`` names the level; each agent to compare must have been trained on it. Without
it, the level is the one every agent to compare was trained on (its metadata's ``env.id``,
:func:`train.agent_files.read_metadata`); agents of different levels are refused in one
line naming them. An agents folder with no agent keeps the default level
(:data:`acld_gym.ENV_ID`), so the command says that the folder has none.
:func:`check_agents_fit` checks the loaded agents against the level's env itself (their
observation fingerprint) before the first episode.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from acld_gym import ENV_ID
from acld_gym.envs.presets import preset
from baselines.evaluation.rollout import check_compatible

from .agent_dirs import agent_folders, agent_mesh
from .agent_files import read_metadata

__all__ = [
    "Level",
    "agent_level",
    "resolve_level",
    "level_config",
    "check_agents_fit",
]


@dataclass(frozen=True)
class Level:
    """The level of a comparison: its ``env_id``, the ``names`` of the agents to compare on
    it and ``how`` it was chosen (said in the command's first line)."""

    env_id: str
    names: tuple[str, ...]
    how: str

    def first_line(self) -> str:
        """The command's first line: which agents, on which level, and why that level."""
        who = ", ".join(self.names) if self.names else "no agent"
        return f"comparing {who} with the references on {self.env_id} ({self.how})"


def agent_level(path: str | Path) -> tuple[str, str]:
    """``(env id, mesh)`` the agent folder ``path`` was trained on (its metadata,
    :func:`train.agent_dirs.agent_mesh`); ``OSError`` / :class:`train.agent.AgentFileError`
    naming the folder or the file if it does not read."""
    env = read_metadata(path)["env"]
    return env["id"], agent_mesh(env)


def resolve_level(
    directory: str | Path,
    only=(),
    env_id: str | None = None,
    mesh: str | None = None,
) -> Level:
    """The level and the agents of a comparison of the agents folder ``directory``.

    Parameters
    ----------
    directory
        The agents folder (``--agents``), an existing directory.
    only
        The agents to compare (``--only``); empty: every agent of the folder trained on the
        comparison's mesh.
    env_id
        ``--env-id`` (a registered id, already checked), or None: the agents' level.
    mesh
        ``--mesh``, or None: the level's.

    Returns
    -------
    Level
        The id, the agents on it (for ``--only``: those named) and how the id was chosen.

    Raises
    ------
    ValueError
        One line: agents of different levels (without ``env_id``) or an agent of another
        level than ``env_id``, naming each agent and its level; a folder that does not read.
    OSError
        A named agent's folder that is missing or unreadable.
    """
    directory = Path(directory)
    if only:
        levels = {name: agent_level(directory / name) for name in only}
    else:  # each metadata read once; one that does not read names its fault here
        levels = {
            n: agent_level(directory / n) if env is None else (env["id"], agent_mesh(env))
            for n, env in agent_folders(directory)
        }
    if not only and mesh is not None:  # --mesh chooses the agents, as before levels
        levels = {n: lv for n, lv in levels.items() if lv[1] == mesh}
    ids = {n: lv[0] for n, lv in levels.items()}
    if env_id is not None:
        other = {n: i for n, i in ids.items() if i != env_id}
        if other:
            listed = ", ".join(f"{n!r} was trained on {i}" for n, i in other.items())
            raise ValueError(
                f"--env-id {env_id}: agent{'s' * (len(other) > 1)} {listed}, not on --env-id "
                f"{env_id} (compare an agent on its own level: leave out --env-id, or --only "
                "the agents of one level)"
            )
        how = "--env-id"
    elif len(set(ids.values())) > 1:
        listed = ", ".join(f"{n} ({i})" for n, i in ids.items())
        raise ValueError(
            f"--agents: {str(directory)!r} holds agents of different levels: {listed}; compare "
            "one level at a time (--only the agents of one level, or a folder per level)"
        )
    elif ids:
        env_id, how = next(iter(ids.values())), "the level the agents were trained on"
    else:
        env_id, how = ENV_ID, "the default level"
    if not only:  # the folder's agents on the comparison's mesh
        mesh = mesh or level_config(env_id).mesh
        levels = {n: lv for n, lv in levels.items() if lv[1] == mesh}
    return Level(env_id, tuple(levels), how)


def level_config(env_id: str, mesh: str | None = None, param_noise: float | None = None):
    """The :class:`acld_gym.envs.config.EnvConfig` of ``env_id`` with ``--mesh`` and
    ``--param-noise`` where given (None: the level's); ``ValueError`` naming the flag that
    the level does not accept."""
    config, changes = preset(env_id), {}
    given = (("--mesh", "mesh", mesh), ("--param-noise", "param_noise", param_noise))
    for flag, key, value in given:
        if value is not None:
            changes[key] = value
            try:
                config = preset(env_id, **changes)
            except ValueError as exc:
                raise ValueError(f"{flag}: {exc}") from None
    return config


def check_agents_fit(agents: dict, env) -> None:
    """``ValueError`` (one line, naming the agent) unless every agent (name -> policy) takes
    ``env``'s observation (:func:`baselines.evaluation.rollout.check_compatible`)."""
    for agent in agents.values():
        check_compatible(agent, env)
