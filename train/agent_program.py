"""The deterministic actor of a trained agent as data: :class:`ActorProgram`, a JSON list
of numpy operations and their arrays (what ``policy.npz`` and the metadata's ``actor`` hold),
checked as it is built; :func:`linear_program`, the saturated linear actor as one; the names
of an agent folder's files; :func:`observation_width`, the width the metadata records.
:mod:`train.agent` (the agent folder) and :mod:`train.sb3_export` (an SB3 model's actor)
build on it; every name is importable from :mod:`train.agent` too."""

from __future__ import annotations

import numpy as np

from .agent_schema import AgentFileError, check_ops
from .direction import direction_features

__all__ = [
    "ActorProgram",
    "linear_program",
    "observation_width",
    "POLICY_FILE",
    "META_FILE",
    "MODEL_FILE",
    "STATS_FILE",
    "CURVE_FILE",
]

POLICY_FILE = "policy.npz"
META_FILE = "metadata.json"
#: SB3's files, for resuming training only (pickled: never read by TrainedAgent).
MODEL_FILE = "model.zip"
STATS_FILE = "vecnormalize.pkl"
#: A trained agent's learning curve (``timesteps,case,ise``: the evaluations of its run).
CURVE_FILE = "learning_curve.csv"


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
    """The width of the input an agent's metadata records: the ``"estimate"`` observation
    (the design order + 1) and the commands it remembers (``commands``, checked by
    :func:`train.agent_schema.check_metadata`), or None when it does not say."""
    obs = metadata.get("observation")
    if (
        isinstance(obs, dict)
        and obs.get("obs_mode") == "estimate"
        and isinstance(obs.get("xr_scale"), list)
    ):
        return len(obs["xr_scale"]) + 1 + int((metadata.get("commands") or {}).get("observed", 0))
    return None
