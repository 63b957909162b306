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

from pathlib import Path

import numpy as np

from .agent_files import (
    MAX_CURVE_BYTES,
    MAX_METADATA_BYTES,
    MAX_POLICY_BYTES,
    AgentFolder,
    read_arrays,
    read_files,
    write_folder,
)
from .agent_schema import FORMAT, AgentFileError, check_ops, parse_metadata
from .direction import direction_features
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

POLICY_FILE = "policy.npz"
META_FILE = "metadata.json"
#: SB3's files, for resuming training only (pickled: never read by TrainedAgent).
MODEL_FILE = "model.zip"
STATS_FILE = "vecnormalize.pkl"
#: A trained agent's learning curve (``timesteps,case,ise``: the evaluations of its run).
CURVE_FILE = "learning_curve.csv"


def versions() -> dict[str, str]:
    """Versions of Python and the packages a training run used (its metadata)."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    import acld_gym

    out = {"python": platform.python_version(), "acld_gym": acld_gym.__version__}
    for name in ("gymnasium", "stable_baselines3", "torch", "numpy", "scipy"):
        try:
            out[name] = version(name.replace("_", "-"))
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


class ActorProgram:
    """The deterministic actor as a list of numpy operations on the raw observation.

    ``ops`` is JSON-able: ``{"op": "normalize", "clip": c, "eps": e}`` (arrays
    ``mean``, ``var``), ``{"op": "direction"}`` (:func:`train.features.direction_features`),
    ``{"op": "linear"}`` (arrays ``W{i}``, ``b{i}``), ``{"op": "tanh" | "relu"}``,
    ``{"op": "clip", "low": l, "high": h}``. The output is the action in [-1, 1].

    The operations must be well formed (:func:`train.agent_schema.check_ops`), every array
    finite and of the shape its operation needs, the first layer's input ``n_obs`` wide if
    given (the observation's width) and the last layer's output one action; otherwise
    :class:`AgentFileError` names the operation or the array.
    """

    def __init__(self, ops: list[dict], arrays: dict[str, np.ndarray], n_obs: int | None = None):
        self.ops = [dict(op) for op in check_ops(list(ops), META_FILE)]
        self.arrays = {k: np.asarray(v, dtype=np.float64) for k, v in arrays.items()}
        for key in self.needed_arrays(self.ops):
            if key not in self.arrays:
                raise AgentFileError(f"{POLICY_FILE}: missing array {key!r}")
        self.check_width(n_obs)

    @staticmethod
    def needed_arrays(ops: list[dict]) -> list[str]:
        """The arrays the operations ``ops`` use, in order; fills in each linear
        operation's default ``layer`` (the count of linear operations before it)."""
        out, layer = [], 0
        for op in ops:
            if op["op"] == "linear":
                op.setdefault("layer", layer)
                layer += 1
                out += [f"W{op['layer']}", f"b{op['layer']}"]
            elif op["op"] == "normalize":
                out += ["mean", "var"]
        return list(dict.fromkeys(out))

    def check_width(self, n_obs: int | None) -> None:
        """Every array the operations use is finite and of the shape its place in the
        program fixes: ``mean``, ``var`` (d,), ``W{i}`` (width in, width out), ``b{i}``
        (width out,), the output one action; d is ``n_obs`` (or the first array's width).
        With ``n_obs`` given, the actor must also give a finite action for moderate
        observations (zero, +/-1 and +/-1000 in every entry): weights that overflow are
        refused here, not met as a NaN voltage mid-episode. :class:`AgentFileError` naming
        the array otherwise."""
        for key, value in self.arrays.items():
            if not np.all(np.isfinite(value)):
                raise AgentFileError(f"{POLICY_FILE}: array {key!r} has non-finite values")
        width = n_obs
        for op in self.ops:
            kind = op["op"]
            if kind == "normalize":
                width = self._expect("mean", (width,), width)[0]
                self._expect("var", (width,), width)
                if np.any(self.arrays["var"] < 0):
                    raise AgentFileError(f"{POLICY_FILE}: array 'var' has negative values")
                if np.any(self.arrays["var"] + op["eps"] <= 0):
                    raise AgentFileError(
                        f"{POLICY_FILE}: array 'var' has zeros and the normalize operation "
                        "no eps (a division by zero)"
                    )
            elif kind == "direction" and width is not None:
                width += 1
            elif kind == "linear":
                w, b = f"W{op['layer']}", f"b{op['layer']}"
                width_in, width = self._expect(w, (width, None), width, ndim=2)
                self._expect(b, (width,), width)
        if width is not None and width != 1:
            raise AgentFileError(
                f"{POLICY_FILE}: the actor's last layer gives {width} values, expected one action"
            )
        if n_obs is not None:
            probe = np.array([[0.0], [1.0], [-1.0], [1e3], [-1e3]]) * np.ones((1, n_obs))
            with np.errstate(all="ignore"):
                out = self._raw(probe)
            if not np.all(np.isfinite(out)):
                raise AgentFileError(
                    f"{POLICY_FILE}: the actor's arrays overflow: a non-finite action for a "
                    "moderate observation"
                )

    def _expect(self, key: str, shape: tuple, width: int | None, ndim: int = 1) -> tuple:
        """The shape of array ``key``, checked against ``shape`` (None: any size)."""
        got = self.arrays[key].shape
        if len(got) != ndim or any(
            w is not None and g != w for g, w in zip(got, shape, strict=True)
        ):
            want = ", ".join("n" if w is None else str(w) for w in shape)
            raise AgentFileError(
                f"{POLICY_FILE}: array {key!r} has shape {got}, expected "
                f"({want}{',' if ndim == 1 else ''}) (the actor's width "
                f"there: {width})"
            )
        return got

    @property
    def input_width(self) -> int:
        """The observation width d the program reads (its first array's)."""
        kinds = [op["op"] for op in self.ops]
        i = kinds.index("linear")  # (check_ops: there is one)
        if "normalize" in kinds[:i]:
            i = kinds.index("normalize")
            return int(self.arrays["mean"].shape[0]) - kinds[:i].count("direction")
        return int(self.arrays[f"W{self.ops[i]['layer']}"].shape[0]) - kinds[:i].count("direction")

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """Actions in [-1, 1], shape (n, 1), for raw observations (n, d); ``ValueError`` if
        a finite observation gives a non-finite action (weights that overflow on it)."""
        obs = np.asarray(obs, dtype=np.float64)
        with np.errstate(all="ignore"):
            a = self._raw(obs)
        if not np.all(np.isfinite(a)) and np.all(np.isfinite(obs)):
            raise ValueError("the actor's arrays overflow on this observation: a non-finite action")
        return a

    def _raw(self, obs: np.ndarray) -> np.ndarray:
        """The program on ``obs`` (n, d), actions clipped to [-1, 1], NaN left as NaN."""
        z = obs
        a = self.arrays
        for op in self.ops:
            kind = op["op"]
            if kind == "normalize":
                z = np.clip(
                    (z - a["mean"]) / np.sqrt(a["var"] + op["eps"]), -op["clip"], op["clip"]
                )
            elif kind == "direction":
                z = direction_features(z)
            elif kind == "linear":
                z = z @ a[f"W{op['layer']}"] + a[f"b{op['layer']}"]
            elif kind == "tanh":
                z = np.tanh(z)
            elif kind == "relu":
                z = np.maximum(z, 0.0)
            else:
                z = np.clip(z, op["low"], op["high"])
        return np.clip(z, -1.0, 1.0).reshape(-1, 1)


def linear_program(
    theta: np.ndarray, transform: np.ndarray | None = None, features: str | None = None
) -> ActorProgram:
    r"""The saturated linear actor :math:`a = \mathrm{clip}(w \cdot f + b, -1, 1)` as an
    :class:`ActorProgram`, with ``theta = [w, b]`` and f the features of
    :math:`u = T^T z` (``transform`` T, identity if None): u itself (``features=None``) or
    ``"direction"``, :math:`[u/|u|, \log|u|]`. The teacher-free random search's actor
    (:class:`train.core.search.LinearDirectionActor`)."""
    theta = np.asarray(theta, dtype=np.float64)
    w, b = theta[:-1, None], theta[-1:]
    if features not in (None, "direction"):
        raise ValueError(f"features must be None or 'direction', got {features!r}")
    if features is None:  # one layer: (z T) w + b = z (T w) + b
        W = w if transform is None else np.asarray(transform, np.float64) @ w
        return ActorProgram(
            [{"op": "linear", "layer": 0}, {"op": "clip", "low": -1.0, "high": 1.0}],
            {"W0": W, "b0": b},
        )
    ops: list[dict] = []
    arrays: dict[str, np.ndarray] = {}
    if transform is not None:
        T = np.asarray(transform, np.float64)
        ops.append({"op": "linear", "layer": 0})
        arrays.update(W0=T, b0=np.zeros(T.shape[1]))
    layer = len(ops)
    ops += [
        {"op": "direction"},
        {"op": "linear", "layer": layer},
        {"op": "clip", "low": -1.0, "high": 1.0},
    ]
    arrays.update({f"W{layer}": w, f"b{layer}": b})
    return ActorProgram(ops, arrays)


def observation_width(metadata: dict) -> int | None:
    """The width of the observation an agent's metadata records (the ``"estimate"``
    observation: the design order + 1), or None when it does not say."""
    obs = metadata.get("observation")
    if (
        isinstance(obs, dict)
        and obs.get("obs_mode") == "estimate"
        and isinstance(obs.get("xr_scale"), list)
    ):
        return len(obs["xr_scale"]) + 1
    return None


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
        meta = dict(self.metadata, format=FORMAT, actor=self.actor.ops)
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
        import gymnasium as gym

        import acld_gym  # noqa: F401  (registers the ids)
        from acld_gym.envs.fingerprint import fingerprint_differences, observation_fingerprint
        from acld_gym.envs.presets import check_env_id

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
        finally:
            env.close()
        if diff:
            raise AgentFileError(
                f"agent {str(where)!r} was trained on another observation "
                f"than {env_id}'s today: " + "; ".join(diff)
            )
        try:
            self.actor.check_width(width)
        except AgentFileError as exc:
            raise AgentFileError(f"{where}/{exc}") from None

    # --- policy -----------------------------------------------------------------------
    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: ``(voltages, state)``, shape (n, 1) for a batch or (1,)."""
        if not deterministic:
            raise ValueError(
                "deterministic must be True: TrainedAgent evaluates the deterministic policy"
            )
        obs = np.asarray(observation, dtype=np.float32)
        width = self.actor.input_width
        if obs.shape not in ((width,),) and not (obs.ndim == 2 and obs.shape[1] == width):
            raise ValueError(
                f"observation: expected shape ({width},) or (n, {width}) (the observation of "
                f"{self.metadata.get('env', {}).get('id', 'its env')}), got shape {obs.shape}"
            )
        batched = obs.ndim == 2
        obs2 = np.atleast_2d(obs)
        v = self.map(self.actor(obs2), obs2)
        return (v if batched else v[0]), state
