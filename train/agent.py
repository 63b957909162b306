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

:meth:`TrainedAgent.load` reads only those two files. It refuses an agent whose
fingerprint does not match what that env's observation is today, on this machine
(another basis, mesh, observer or scaling), and :func:`baselines.evaluate.rollout`
refuses to run it in an env whose observation differs: an agent never acts on
coordinates it was not trained on. Training runs also keep SB3's ``model.zip`` and
``vecnormalize.pkl`` for resuming training; loading *those* unpickles code, so only
load them from a source you trust (``TrainedAgent`` never does).
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from acld_gym.util.atomic import write_atomic, write_json

from .direction import direction_features
from .voltage import VoltageMap

__all__ = [
    "TrainedAgent",
    "ActorProgram",
    "AgentFileError",
    "export_sb3",
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
#: Version of the agent format.
FORMAT = 2


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


class AgentFileError(ValueError):
    """An agent directory's file is missing, damaged or inconsistent (names the file)."""


class ActorProgram:
    """The deterministic actor as a list of numpy operations on the raw observation.

    ``ops`` is JSON-able: ``{"op": "normalize", "clip": c, "eps": e}`` (arrays
    ``mean``, ``var``), ``{"op": "direction"}`` (:func:`train.features.direction_features`),
    ``{"op": "linear"}`` (arrays ``W{i}``, ``b{i}``), ``{"op": "tanh" | "relu"}``,
    ``{"op": "clip", "low": l, "high": h}``. The output is the action in [-1, 1].

    Every array must be finite and of the shape its operation needs, the first layer's
    input ``n_obs`` wide if given (the observation's width) and the last layer's output
    one action; otherwise :class:`AgentFileError` names the array.
    """

    _KINDS = ("normalize", "direction", "linear", "tanh", "relu", "clip")

    def __init__(self, ops: list[dict], arrays: dict[str, np.ndarray], n_obs: int | None = None):
        self.ops = [dict(op) for op in ops]
        self.arrays = {k: np.asarray(v, dtype=np.float64) for k, v in arrays.items()}
        layer = 0
        for op in self.ops:
            kind = op.get("op")
            if kind not in self._KINDS:
                raise AgentFileError(f"{META_FILE}: actor: unknown operation {kind!r}")
            if kind == "linear":
                op.setdefault("layer", layer)
                layer += 1
                for key in (f"W{op['layer']}", f"b{op['layer']}"):
                    if key not in self.arrays:
                        raise AgentFileError(f"{POLICY_FILE}: missing array {key!r}")
            if kind == "normalize" and not {"mean", "var"} <= set(self.arrays):
                raise AgentFileError(f"{POLICY_FILE}: normalize needs 'mean' and 'var'")
        self._check_arrays(n_obs)

    def _check_arrays(self, n_obs: int | None) -> None:
        """Every array the operations use is finite and of the shape its place in the
        program fixes: ``mean``, ``var`` (d,), ``W{i}`` (width in, width out), ``b{i}``
        (width out,), the output one action; d is ``n_obs`` (or the first array's width)."""
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

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """Actions in [-1, 1], shape (n, 1), for raw observations (n, d)."""
        z = np.asarray(obs, dtype=np.float64)
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


def actor_extractor(model):
    """The features extractor of an SB3 model's deterministic actor (what
    :func:`actor_parts` returns first), whatever the layers after it."""
    pol = model.policy
    actor = getattr(pol, "actor", None)
    if actor is not None:  # SAC, TQC, CrossQ, TD3
        return actor.features_extractor
    if hasattr(pol, "mlp_extractor"):  # PPO / A2C
        return pol.pi_features_extractor
    return pol.features_extractor  # ARS (sb3-contrib)


def actor_parts(model) -> tuple[Any, list, bool]:
    """The deterministic actor of an SB3 model as ``(features extractor, layers in order,
    squash)``: ``squash`` is True where SB3 applies a tanh after the last layer. One walk
    for :func:`export_sb3` and for folding a whitening into the first linear layer
    (:func:`train.bench.sb3_train.fold_whitening`)."""
    import torch.nn as nn

    pol = model.policy
    extractor = actor_extractor(model)
    actor = getattr(pol, "actor", None)
    if actor is not None and hasattr(actor, "latent_pi"):  # SAC, TQC, CrossQ: tanh(mu(latent))
        mu = actor.mu
        layers = [*actor.latent_pi, *(mu if isinstance(mu, nn.Sequential) else [mu])]
        return extractor, layers, True
    if actor is not None and hasattr(actor, "mu"):  # TD3: mu is the whole net, Tanh last
        return extractor, list(actor.mu), False
    if not hasattr(pol, "mlp_extractor"):  # ARS (sb3-contrib): action_net is the actor
        return extractor, list(pol.action_net), False
    # PPO / A2C: Gaussian mean, clipped to the box
    return extractor, [*pol.mlp_extractor.policy_net, pol.action_net], bool(pol.squash_output)


def export_sb3(model, obs_norm=None) -> ActorProgram:
    """The deterministic actor of an SB3 ``MlpPolicy`` (PPO, SAC, TD3, TQC, CrossQ, ARS,
    ...) and its ``VecNormalize`` observation statistics as an :class:`ActorProgram` (equal
    to SB3's ``predict`` to float32 round-off; tests/train/test_distill.py and, for
    CrossQ's batch renormalisation, tests/train/test_benchmark.py)."""
    import torch.nn as nn
    from stable_baselines3.common.torch_layers import FlattenExtractor

    from .features import DirectionFeatures, DropLast

    ops: list[dict] = []
    arrays: dict[str, np.ndarray] = {}
    if obs_norm is not None and getattr(obs_norm, "norm_obs", False):
        ops.append(
            {"op": "normalize", "clip": float(obs_norm.clip_obs), "eps": float(obs_norm.epsilon)}
        )
        arrays["mean"] = obs_norm.obs_rms.mean.copy()
        arrays["var"] = obs_norm.obs_rms.var.copy()
    extractor, layers, squash = actor_parts(model)
    if isinstance(extractor, DirectionFeatures):
        ops.append({"op": "direction"})
    elif isinstance(extractor, DropLast):  # an asymmetric agent: the actor never read the
        pass  # appended log(reward scale), and the deployed env does not append it
    elif not isinstance(extractor, FlattenExtractor):
        raise TypeError(
            f"export_sb3 supports the flatten or direction features only, got "
            f"{type(extractor).__name__}"
        )
    layer = 0
    for m in layers:
        if isinstance(m, nn.Linear):
            arrays[f"W{layer}"] = m.weight.detach().double().numpy().T.copy()
            arrays[f"b{layer}"] = m.bias.detach().double().numpy().copy()
            ops.append({"op": "linear", "layer": layer})
            layer += 1
        elif _is_batch_renorm(m):  # CrossQ's; in eval mode an affine map of each feature
            w, b = _batch_renorm_affine(m)
            arrays[f"W{layer}"] = np.diag(w)
            arrays[f"b{layer}"] = b
            ops.append({"op": "linear", "layer": layer})
            layer += 1
        elif isinstance(m, nn.Tanh):
            ops.append({"op": "tanh"})
        elif isinstance(m, nn.ReLU):
            ops.append({"op": "relu"})
        elif isinstance(m, nn.Hardtanh):
            ops.append({"op": "clip", "low": float(m.min_val), "high": float(m.max_val)})
        else:
            raise TypeError(f"export_sb3: unsupported layer {m!r}")
    if squash:
        ops.append({"op": "tanh"})
    return ActorProgram(ops, arrays)


def _is_batch_renorm(m) -> bool:
    """Whether ``m`` is sb3-contrib's ``BatchRenorm`` (CrossQ's layers)."""
    try:
        from sb3_contrib.common.torch_layers import BatchRenorm
    except ImportError:  # sb3-contrib not installed: no BatchRenorm to meet
        return False
    return isinstance(m, BatchRenorm)


def _batch_renorm_affine(m) -> tuple[np.ndarray, np.ndarray]:
    r"""The per-feature map :math:`x \mapsto w x + b` of sb3-contrib's ``BatchRenorm`` in
    evaluation mode, as SB3's ``predict`` runs it: :math:`w = \gamma / \sqrt{\sigma^2 +
    \epsilon}`, :math:`b = \beta - w \mu` with the running mean :math:`\mu` and variance
    :math:`\sigma^2` (``ra_mean``, ``ra_var``) and the affine ``scale`` :math:`\gamma` and
    ``bias`` :math:`\beta` (1 and 0 if not ``affine``)."""

    def arr(t):
        return t.detach().double().numpy().copy()

    mean, var = arr(m.ra_mean), arr(m.ra_var)
    gamma, beta = (arr(m.scale), arr(m.bias)) if m.affine else (1.0, 0.0)
    w = np.broadcast_to(gamma / np.sqrt(var + float(m.eps)), mean.shape).copy()
    return w, np.broadcast_to(beta, mean.shape) - w * mean


def linear_program(
    theta: np.ndarray, transform: np.ndarray | None = None, features: str | None = None
) -> ActorProgram:
    r"""The saturated linear actor :math:`a = \mathrm{clip}(w \cdot f + b, -1, 1)` as an
    :class:`ActorProgram`, with ``theta = [w, b]`` and f the features of
    :math:`u = T^T z` (``transform`` T, identity if None): u itself (``features=None``) or
    ``"direction"``, :math:`[u/|u|, \log|u|]`. The teacher-free random search's actor
    (:class:`train.bench.search.LinearDirectionActor`)."""
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
    def save(self, directory: str | Path) -> Path:
        """Write ``policy.npz`` and ``metadata.json`` (atomically) to ``directory``."""
        d = Path(directory)
        meta = dict(self.metadata, format=FORMAT, actor=self.actor.ops)
        write_atomic(d / POLICY_FILE, lambda fh: np.savez(fh, **self.actor.arrays))
        write_json(d / META_FILE, meta)
        return d

    @classmethod
    def load(
        cls, directory: str | Path, name: str | None = None, check: bool = True
    ) -> TrainedAgent:
        """Load an agent directory without executing anything from it.

        With ``check`` (default), the recorded observation fingerprint is compared with
        the observation of the env it names, as defined by this installation on this
        machine; a mismatch raises :class:`AgentFileError` saying what differs.
        """
        d = Path(directory)
        if not d.is_dir():
            raise FileNotFoundError(f"agent directory {str(d)!r} does not exist")
        meta_path, pol_path = d / META_FILE, d / POLICY_FILE
        for f in (meta_path, pol_path):
            if not f.is_file():
                raise FileNotFoundError(f"agent directory {str(d)!r} lacks {f.name}")
        try:
            meta = json.loads(meta_path.read_text())
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise AgentFileError(f"{meta_path}: not valid JSON ({exc})") from None
        if not isinstance(meta, dict) or not {"actor", "observation", "env"} <= set(meta):
            raise AgentFileError(
                f"{meta_path}: expected an agent's metadata with 'actor', 'observation' and 'env'"
            )
        try:
            with np.load(pol_path, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
        except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
            raise AgentFileError(f"{pol_path}: not a readable numpy archive ({exc})") from None
        try:
            actor = ActorProgram(meta["actor"], arrays, observation_width(meta))
        except AgentFileError as exc:
            raise AgentFileError(f"{d}/{exc}") from None
        agent = cls(actor, meta, name or meta.get("algo", "agent"), d)
        if check:
            agent.check_current()
        return agent

    def check_current(self) -> None:
        """Raise :class:`AgentFileError` if the env the agent names observes differently
        today (:mod:`acld_gym.envs.fingerprint`)."""
        import gymnasium as gym

        import acld_gym  # noqa: F401  (registers the ids)
        from acld_gym.envs.fingerprint import fingerprint_differences, observation_fingerprint

        env_meta = self.metadata["env"]
        env = gym.make(env_meta["id"], **env_meta.get("kwargs", {}))
        try:
            diff = fingerprint_differences(
                self.observation_fingerprint, observation_fingerprint(env)
            )
        finally:
            env.close()
        if diff:
            where = self.directory if self.directory is not None else self.name
            raise AgentFileError(
                f"agent {str(where)!r} was trained on another observation "
                f"than {env_meta['id']}'s today: " + "; ".join(diff)
            )

    # --- policy -----------------------------------------------------------------------
    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: ``(voltages, state)``, shape (n, 1) for a batch or (1,)."""
        if not deterministic:
            raise ValueError(
                "deterministic must be True: TrainedAgent evaluates the deterministic policy"
            )
        obs = np.asarray(observation, dtype=np.float32)
        batched = obs.ndim == 2
        obs2 = np.atleast_2d(obs)
        v = self.map(self.actor(obs2), obs2)
        return (v if batched else v[0]), state
