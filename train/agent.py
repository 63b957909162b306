"""A trained agent as a policy with SB3's ``predict`` protocol in volts, so
:mod:`baselines.evaluate` treats it exactly like LQR, SMC and MPC.

An agent directory holds what the policy needs in formats that cannot execute
anything when read:

* ``policy.npz``: the deterministic actor as numpy arrays (the observation
  normalization, the layers' weights), read with ``allow_pickle=False``;
* ``metadata.json``: how it was made (algorithm, teacher or none, command, config,
  versions), the actor's program (which operation uses which arrays), and the
  **observation fingerprint** of the env it was trained on
  (:mod:`acld_gym.envs.fingerprint`).

:meth:`TrainedAgent.load` reads only those two files, and treats them as data from an
unknown source: it never imports or executes anything and never leaves the folder. The
env id the metadata names must be one of this package's registered ids, matched as a
string (:mod:`train.agent_schema`; Gymnasium's ``"module:Env"`` form would import
``module``); no symbolic link is followed; the archive's members are checked by name and
declared size against the actor program before anything is decompressed
(:mod:`train.agent_files`). Every fault is an :class:`AgentFileError` naming the file and
the field. It refuses an agent whose fingerprint does not match what that env's
observation is today, on this machine (another basis, mesh, observer or scaling), and
:func:`baselines.evaluate.rollout` refuses to run it in an env whose observation differs:
an agent never acts on coordinates it was not trained on.

:meth:`TrainedAgent.save` writes the folder whole: built in a temporary sibling and
swapped in with one rename, so a reader (or a full disk) sees the old agent or the new
one. Training runs also keep SB3's ``model.zip`` and ``vecnormalize.pkl`` for resuming
training; loading *those* unpickles code, so only load them from a source you trust
(``TrainedAgent`` never does).
"""

from __future__ import annotations

import platform
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import gymnasium as gym
import numpy as np

import acld_gym  # registers the ids that check_current makes
from acld_gym.envs.fingerprint import fingerprint_differences, observation_fingerprint
from acld_gym.envs.presets import check_env_id

from .agent_files import (
    MAX_CURVE_BYTES,
    MAX_METADATA_BYTES,
    MAX_POLICY_BYTES,
    AgentFolder,
    read_arrays,
    read_files,
    write_folder,
)
from .agent_program import (
    CURVE_FILE,
    META_FILE,
    MODEL_FILE,
    POLICY_FILE,
    STATS_FILE,
    ActorProgram,
    linear_program,
    observation_width,
)
from .agent_schema import FORMAT, FORMAT_PLAIN, AgentFileError, check_commands, parse_metadata
from .commands import CommandMemory, memory_of
from .sb3_export import actor_extractor, actor_parts, export_sb3
from .voltage import VoltageMap

#: Largest ``policy.npz`` on disk: the arrays' limit and room for the archive's directory.
_MAX_ARCHIVE_BYTES = MAX_POLICY_BYTES + (1 << 20)

__all__ = [
    "TrainedAgent",
    "ActorProgram",
    "AgentFileError",
    "export_sb3",
    "actor_extractor",
    "actor_parts",
    "linear_program",
    "observation_width",
    "POLICY_FILE",
    "META_FILE",
    "MODEL_FILE",
    "STATS_FILE",
    "CURVE_FILE",
    "versions",
]


def versions() -> dict[str, str]:
    """Versions of Python and the packages a training run used (its metadata)."""
    out = {"python": platform.python_version(), "acld_gym": acld_gym.__version__}
    for name in ("gymnasium", "stable_baselines3", "torch", "numpy", "scipy"):
        try:
            out[name] = version(name.replace("_", "-"))
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


class TrainedAgent:
    """An agent directory (module docstring) as a policy on the env's raw observation.

    ``predict`` runs the :class:`ActorProgram` and maps its action to volts with the
    same :class:`train.voltage.VoltageMap` as in training (its ``residual`` and
    ``action_headroom`` from the metadata; an agent without them: none and 1).
    """

    def __init__(
        self,
        actor: ActorProgram,
        metadata: dict,
        name: str = "agent",
        directory: Path | None = None,
    ):
        if not isinstance(metadata, dict):
            raise TypeError(f"metadata: expected a dict, got {type(metadata).__name__}")
        self.actor = actor
        self.metadata = dict(metadata)
        self.name = name
        self.directory = directory
        try:
            self.map = VoltageMap(
                self.metadata.get("residual"), headroom=self.metadata.get("action_headroom", 1.0)
            )
        except ValueError as exc:
            raise AgentFileError(f"{META_FILE}: {exc}") from None
        commands = self.metadata.get("commands")
        if commands is not None:
            check_commands(commands, META_FILE)
        #: Its memory of its own commands (trained with ``observe_commands``), or None.
        self.commands = None if commands is None else CommandMemory(**commands)

    # --- what it was trained on --------------------------------------------------------
    @property
    def observation_fingerprint(self) -> dict | None:
        """The observation it was trained on (checked by :func:`baselines.evaluate.rollout`;
        None for an agent built in memory without one)."""
        return self.metadata.get("observation")

    @property
    def training(self) -> str:
        """How it was trained: ``"from scratch"`` or ``"DAgger from <teacher> + RL"``."""
        return self.metadata.get("training", "unknown")

    # --- files ------------------------------------------------------------------------
    def save(self, directory: str | Path, files: dict[str, str] | None = None) -> Path:
        """Write the agent folder ``directory`` whole: ``policy.npz``, ``metadata.json``
        and the text ``files`` (name: text, e.g. its ``learning_curve.csv``), built in a
        temporary sibling and swapped in with one rename
        (:func:`train.agent_write.write_folder`): what was there before is replaced, or,
        if the write fails, left as it was. ``ValueError`` if ``directory`` holds other
        files than an agent's or a training run's."""
        fmt = FORMAT if self.commands is not None else FORMAT_PLAIN  # older readers: 1-2
        meta = dict(self.metadata, format=fmt, actor=self.actor.ops)
        return write_folder(directory, self.actor.arrays, meta, dict(files or {}))

    @classmethod
    def load(
        cls, directory: str | Path, name: str | None = None, check: bool = True
    ) -> TrainedAgent:
        """Load an agent directory as data (module docstring): nothing from it is
        imported or executed, no link followed, no member decompressed before it is
        checked. ``FileNotFoundError`` if ``directory`` does not exist; every fault of
        its files an :class:`AgentFileError` naming the file and the field.

        With ``check`` (default), the recorded observation fingerprint is compared with
        the observation of the env it names, as defined by this installation on this
        machine; a mismatch raises :class:`AgentFileError` saying what differs.
        """
        d = Path(directory)
        files = read_files(d, {META_FILE: MAX_METADATA_BYTES, POLICY_FILE: _MAX_ARCHIVE_BYTES})
        meta_bytes, policy_bytes = files[META_FILE], files[POLICY_FILE]
        meta = parse_metadata(meta_bytes, str(d / META_FILE))
        ops = [dict(op) for op in meta["actor"]]
        arrays = read_arrays(policy_bytes, ActorProgram.needed_arrays(ops), str(d / POLICY_FILE))
        try:
            actor = ActorProgram(ops, arrays, observation_width(meta))
        except AgentFileError as exc:
            raise AgentFileError(f"{d}/{exc}") from None
        agent = cls(actor, meta, name or meta.get("algo") or "agent", d)
        if check:
            agent.check_current()
        return agent

    def learning_curve(self) -> str | None:
        """The text of the folder's ``learning_curve.csv`` (read as :meth:`load` reads, at
        most :data:`train.agent_files.MAX_CURVE_BYTES`, UTF-8), or None if it has none."""
        if self.directory is None:
            return None
        with AgentFolder(self.directory) as folder:
            if not folder.exists(CURVE_FILE):
                return None
            data = folder.read(CURVE_FILE, MAX_CURVE_BYTES)
        try:
            return data.decode("utf-8")
        except UnicodeDecodeError:
            raise AgentFileError(f"{self.directory / CURVE_FILE}: not UTF-8 text") from None

    def check_current(self) -> None:
        """Raise :class:`AgentFileError` if the env the agent names observes differently
        today (:mod:`acld_gym.envs.fingerprint`), or if its settings (``env.kwargs``) are
        not ones that env takes. The id was checked as data when the metadata was read
        (:mod:`train.agent_schema`); it is checked again here before ``gym.make``."""
        where = self.directory if self.directory is not None else self.name
        meta_file = f"{where}/{META_FILE}" if self.directory is not None else str(where)
        env_meta = self.metadata["env"]
        try:
            env_id = check_env_id(env_meta["id"], "env.id")
            env = gym.make(env_id, **env_meta.get("kwargs", {}))
        except (TypeError, ValueError, OverflowError, gym.error.Error) as exc:
            raise AgentFileError(f"{meta_file}: env: {exc}") from None
        try:
            diff = fingerprint_differences(
                self.observation_fingerprint, observation_fingerprint(env)
            )
            width = env.observation_space.shape[0]
            # the memory it must have: the commands that env has in flight
            want = memory_of(env.unwrapped.config.replace(observe_commands=True))
        finally:
            env.close()
        if diff:
            raise AgentFileError(
                f"agent {str(where)!r} was trained on another observation "
                f"than {env_id}'s today: " + "; ".join(diff)
            )
        if self.commands is not None:
            if want is None or want.as_dict() != self.commands.as_dict():
                raise AgentFileError(
                    f"{meta_file}: commands: {self.commands.as_dict()} are not the commands "
                    f"{env_id} has in flight ({None if want is None else want.as_dict()})"
                )
        try:
            self.actor.check_width(width + self.observed_commands)
        except AgentFileError as exc:
            raise AgentFileError(f"{where}/{exc}") from None

    # --- policy -----------------------------------------------------------------------
    @property
    def observed_commands(self) -> int:
        """How many of its own last commands it appends to the env's observation."""
        return 0 if self.commands is None else self.commands.observed

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: ``(voltages, state)``, shape (n, 1) for a batch or (1,). An agent
        trained with ``observe_commands`` (:attr:`commands`) keeps its last commands in
        ``state``: pass it back at every step (None, or ``episode_start`` true, at the
        start of an episode), as to any SB3 recurrent policy; the state of any other
        agent is returned as given."""
        if not deterministic:
            raise ValueError(
                "deterministic must be True: TrainedAgent evaluates the deterministic policy"
            )
        obs = np.asarray(observation, dtype=np.float32)
        width = self.actor.input_width - self.observed_commands
        if obs.shape not in ((width,),) and not (obs.ndim == 2 and obs.shape[1] == width):
            raise ValueError(
                f"observation: expected shape ({width},) or (n, {width}) (the observation of "
                f"{self.metadata.get('env', {}).get('id', 'its env')}), got shape {obs.shape}"
            )
        batched = obs.ndim == 2
        obs2 = np.atleast_2d(obs)
        if self.commands is None:
            v = self.map(self.actor(obs2), obs2)
        else:
            x, state = self.commands.observe(obs2, state, episode_start)
            v = self.map(self.actor(x), obs2)
            state = self.commands.remember(state, v)
        return (v if batched else v[0]), state
