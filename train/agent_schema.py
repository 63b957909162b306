"""What an agent's ``metadata.json`` may hold, checked as data before anything uses it.

:func:`parse_metadata` turns the file's bytes into a dict whose every field the package
reads has the type and range it needs: the env id is one of this package's registered
ids, matched as a plain string and never handed to an importer (Gymnasium's
``"module:Env"`` form would import ``module``); the env's keyword arguments are
:class:`acld_gym.envs.config.EnvConfig` fields; the observation fingerprint has every
entry :func:`acld_gym.envs.fingerprint.observation_fingerprint` records; the actor's
program (:func:`check_ops`) has only known operations with their parameters. Anything
else is an :class:`AgentFileError` naming the file and the field.
"""

from __future__ import annotations

import dataclasses
import json
import math
import numbers

import numpy as np

from acld_gym.envs.config import EnvConfig
from acld_gym.envs.limits import MAX_DELAY
from acld_gym.envs.presets import check_env_id
from acld_gym.util.validate import json_depth, shown
from acld_gym.wrappers import MAX_HEADROOM, check_headroom

__all__ = [
    "AgentFileError",
    "FORMAT",
    "FORMAT_PLAIN",
    "check_commands",
    "MAX_DEPTH",
    "MAX_OPS",
    "OP_KEYS",
    "check_ops",
    "is_real",
    "check_metadata",
    "parse_metadata",
]

#: Version of the agent format this package writes (and the newest it reads).
FORMAT = 3
#: The format of an agent without a memory of its commands (format 3 adds ``commands``),
#: written so that packages reading formats 1-2 still read it.
FORMAT_PLAIN = 2
#: Deepest nesting of lists and objects a metadata file may have (a shipped one has 5).
MAX_DEPTH = 32
#: Most operations an actor program may have (a shipped one has 3).
MAX_OPS = 64
#: Each operation of an actor program and the parameters it takes (all required, except a
#: linear layer's ``layer``, which defaults to the count of linear operations before it).
OP_KEYS: dict[str, tuple[str, ...]] = {
    "normalize": ("clip", "eps"),
    "direction": (),
    "linear": ("layer",),
    "tanh": (),
    "relu": (),
    "clip": ("low", "high"),
}
#: The entries of an observation fingerprint (acld_gym.envs.fingerprint): strings ...
_FINGERPRINT_TEXT = ("env_id", "mesh", "basis", "obs_mode", "observer")
#: ... and arrays (with their number of dimensions); ``dt`` is a positive number.
_FINGERPRINT_ARRAYS = {
    "reduced_A": 2,
    "reduced_B": 1,
    "reduced_C": 1,
    "xr_scale": 1,
    "observer_Lc": 1,
    "observer_Lp": 1,
}
#: Longest label text (``algo``, ``training``, ...) a metadata file may hold.
MAX_TEXT = 200
#: Optional text entries (the package reads them for labels).
_TEXT_FIELDS = ("algo", "training", "teacher", "checkpoint")


class AgentFileError(ValueError):
    """An agent directory's file is missing, damaged or inconsistent (names the file and,
    for metadata, the field)."""


def _fail(where: str, field: str, message: str) -> AgentFileError:
    return AgentFileError(f"{where}: {field}: {message}")


def is_real(value) -> bool:
    """A finite real number (a JSON number, not a bool)."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        return False
    try:
        return math.isfinite(float(value))
    except OverflowError:  # an integer beyond the float range
        return False


def _real(where: str, field: str, value, low: float | None = None, open_low: bool = False):
    if not is_real(value):
        raise _fail(where, field, f"expected a finite number, got {shown(value)}")
    v = float(value)
    if low is not None and (v < low or (open_low and v == low)):
        rel = ">" if open_low else ">="
        raise _fail(where, field, f"expected a number {rel} {low:g}, got {v!r}")
    return v


def _refuse_constant(name: str):
    raise ValueError(f"{name} is not a JSON number")


def parse_metadata(data: bytes, where: str) -> dict:
    """The checked metadata (:func:`check_metadata`) of a ``metadata.json`` read as
    ``data``; :class:`AgentFileError` naming ``where`` and the field otherwise."""
    try:
        meta = json.loads(data.decode("utf-8"), parse_constant=_refuse_constant)
    except RecursionError:
        raise AgentFileError(f"{where}: nested deeper than {MAX_DEPTH} levels") from None
    except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError is a ValueError
        raise AgentFileError(f"{where}: not valid JSON ({shown(str(exc))[1:-1]})") from None
    if json_depth(meta, MAX_DEPTH) > MAX_DEPTH:
        raise AgentFileError(f"{where}: nested deeper than {MAX_DEPTH} levels")
    return check_metadata(meta, where)


def check_metadata(meta, where: str = "metadata.json") -> dict:
    """``meta`` if it is an agent's metadata whose fields the package reads are well
    formed (module docstring); :class:`AgentFileError` naming ``where`` and the field."""
    if not isinstance(meta, dict):
        raise AgentFileError(f"{where}: expected a JSON object, got {type(meta).__name__}")
    missing = [k for k in ("actor", "observation", "env") if k not in meta]
    if missing:
        raise AgentFileError(
            f"{where}: expected an agent's metadata with 'actor', 'observation' and 'env'; "
            f"it lacks {missing}"
        )
    fmt = meta.get("format", FORMAT)
    if isinstance(fmt, bool) or not isinstance(fmt, int) or not 1 <= fmt <= FORMAT:
        raise _fail(where, "format", f"expected an agent format 1 to {FORMAT}, got {shown(fmt)}")
    _check_env(meta["env"], where)
    _check_observation(meta["observation"], meta["env"]["id"], where)
    check_ops(meta["actor"], where)
    for key in _TEXT_FIELDS:  # printed in tables: one printable line
        value = meta.get(key)
        if value is not None and not (
            isinstance(value, str) and value.isprintable() and len(value) <= MAX_TEXT
        ):
            raise _fail(
                where, key, f"expected null or one printable line of text, got {shown(value)}"
            )
    if meta.get("residual") not in (None, "lqr"):
        raise _fail(where, "residual", f"expected null or 'lqr', got {shown(meta['residual'])}")
    if meta.get("commands") is not None:
        check_commands(meta["commands"], where)
    if "action_headroom" in meta:
        headroom = meta["action_headroom"]
        try:  # is_real first: check_headroom cannot take an integer beyond the float range
            check_headroom(headroom if is_real(headroom) else None, "action_headroom")
        except ValueError:
            raise _fail(
                where,
                "action_headroom",
                f"expected a number in [1, {MAX_HEADROOM:g}], got {shown(headroom)}",
            ) from None
    return meta


def check_commands(commands, where: str) -> None:
    """``commands``: ``{"memory": m, "observed": k}``, integers with 1 <= m <= the
    largest delay and 1 <= k <= m (:class:`train.commands.CommandMemory`)."""
    ok = isinstance(commands, dict) and set(commands) == {"memory", "observed"}
    values = [commands.get(k) for k in ("memory", "observed")] if ok else []
    if ok and all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        m, k = values
        ok = 1 <= m <= MAX_DELAY and 1 <= k <= m
    else:
        ok = False
    if not ok:
        raise _fail(
            where,
            "commands",
            f"expected null or {{'memory': m, 'observed': k}} with integers "
            f"1 <= m <= {MAX_DELAY}, 1 <= k <= m, got {shown(commands)}",
        )


def _check_env(env, where: str) -> None:
    """``env``: ``{"id": <a registered id of this package>, "kwargs": {<EnvConfig field>:
    <a JSON value>}}``."""
    if not isinstance(env, dict):
        raise _fail(where, "env", f"expected an object with 'id' and 'kwargs', got {shown(env)}")
    if "id" not in env:
        raise _fail(where, "env.id", "missing (the id of the env the agent was trained on)")
    if not isinstance(env["id"], str) or len(env["id"]) > MAX_TEXT:  # (not echoed in full)
        raise _fail(where, "env.id", f"expected one of this package's ids, got {shown(env['id'])}")
    try:
        check_env_id(env["id"], "env.id")
    except ValueError as exc:
        raise AgentFileError(f"{where}: {exc}") from None
    unknown = sorted(set(env) - {"id", "kwargs"})
    if unknown:
        raise _fail(where, "env", f"unexpected keys {unknown} (expected 'id' and 'kwargs')")
    kwargs = env.get("kwargs", {})
    if not isinstance(kwargs, dict):
        raise _fail(where, "env.kwargs", f"expected an object, got {shown(kwargs)}")
    fields = [f.name for f in dataclasses.fields(EnvConfig)]
    bad = sorted(k for k in kwargs if k not in fields)
    if bad:
        raise _fail(where, "env.kwargs", f"{bad} are not env settings (EnvConfig fields)")


def _check_observation(obs, env_id: str, where: str) -> None:
    """The observation fingerprint: every entry, of its type, made for ``env_id``."""
    if not isinstance(obs, dict):
        raise _fail(where, "observation", f"expected an object, got {shown(obs)}")
    for key in (*_FINGERPRINT_TEXT, "dt", *_FINGERPRINT_ARRAYS):
        if key not in obs:
            raise _fail(where, f"observation.{key}", "missing (the observation fingerprint)")
    for key in _FINGERPRINT_TEXT:
        if not isinstance(obs[key], str):
            raise _fail(where, f"observation.{key}", f"expected a string, got {shown(obs[key])}")
    if obs["env_id"] != env_id:
        raise _fail(
            where, "observation.env_id", f"{obs['env_id']!r} differs from env.id {env_id!r}"
        )
    _real(where, "observation.dt", obs["dt"], 0.0, open_low=True)
    for key, ndim in _FINGERPRINT_ARRAYS.items():
        value = obs[key]
        ok = isinstance(value, list) and _all_reals(value, ndim)
        if ok:
            arr = np.asarray(value, dtype=np.float64) if value else np.zeros(0)
            ok = arr.ndim == ndim or (not value and ndim == 1)
        if not ok:
            shape = "a list of numbers" if ndim == 1 else "a list of equal-length lists of numbers"
            raise _fail(where, f"observation.{key}", f"expected {shape}, got {shown(value)}")
    for key, value in obs.items():
        if key not in _FINGERPRINT_TEXT and key not in _FINGERPRINT_ARRAYS and key != "dt":
            scalar = value is None or isinstance(value, (str, bool)) or is_real(value)
            array = isinstance(value, list) and (_all_reals(value, 1) or _all_reals(value, 2))
            if not (scalar or array):
                raise _fail(
                    where,
                    f"observation.{key}",
                    f"expected a string, a number or a list of numbers, got {shown(value)}",
                )


def _all_reals(value: list, ndim: int) -> bool:
    """Whether ``value`` is a list (of lists, for ``ndim`` 2) of finite numbers, rows of
    one length."""
    if ndim == 1:
        return all(is_real(v) for v in value)
    return (
        all(isinstance(row, list) and _all_reals(row, 1) for row in value)
        and len({len(row) for row in value}) <= 1
    )


def check_ops(ops, where: str = "metadata.json") -> list[dict]:
    """``ops`` if it is an actor program (:class:`train.agent.ActorProgram`): a list of at
    most :data:`MAX_OPS` objects, each ``{"op": <one of OP_KEYS>}`` with exactly the
    parameters :data:`OP_KEYS` names for it, of their types (``normalize``: ``clip`` > 0,
    ``eps`` >= 0; ``clip``: ``low`` <= ``high``; ``linear``: ``layer`` an integer >= 0),
    at least one linear layer; :class:`AgentFileError` naming ``where`` and the operation."""
    if not isinstance(ops, list):
        raise _fail(where, "actor", f"expected a list of operations, got {shown(ops)}")
    if len(ops) > MAX_OPS:
        raise _fail(where, "actor", f"{len(ops)} operations, more than {MAX_OPS}")
    for i, op in enumerate(ops):
        field = f"actor[{i}]"
        if not isinstance(op, dict):
            raise _fail(where, field, f"expected an object with 'op', got {shown(op)}")
        kind = op.get("op")
        if not isinstance(kind, str) or kind not in OP_KEYS:
            raise _fail(
                where, field, f"unknown operation {shown(kind)}; expected one of {list(OP_KEYS)}"
            )
        allowed = {"op", *OP_KEYS[kind]}
        extra = sorted(set(op) - allowed)
        if extra:
            raise _fail(where, field, f"{kind!r} takes {sorted(allowed - {'op'})}, not {extra}")
        required = [k for k in OP_KEYS[kind] if k != "layer"]
        absent = [k for k in required if k not in op]
        if absent:
            raise _fail(where, field, f"{kind!r} needs {required}; it lacks {absent}")
        if kind == "normalize":
            _real(where, f"{field}.clip", op["clip"], 0.0, open_low=True)
            _real(where, f"{field}.eps", op["eps"], 0.0)
        elif kind == "clip":
            low = _real(where, f"{field}.low", op["low"])
            if _real(where, f"{field}.high", op["high"]) < low:
                raise _fail(where, field, f"clip needs low <= high, got {low} > {op['high']}")
        elif kind == "linear" and "layer" in op:
            layer = op["layer"]
            if isinstance(layer, bool) or not isinstance(layer, int) or not 0 <= layer < MAX_OPS:
                want = f"expected an integer in [0, {MAX_OPS}), got {shown(layer)}"
                raise _fail(where, f"{field}.layer", want)
    if not any(op["op"] == "linear" for op in ops):
        raise _fail(where, "actor", "no linear layer (an actor maps the observation to one action)")
    return ops
