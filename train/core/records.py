"""The benchmark's files read back as data: a results table (``results.json``, read by
``python -m train.core.report``), a trial record (``trials/<name>-s<seed>.json``) and a
references cache (``references-<env id>.json``), both read by ``python -m train.benchmark
--resume``.

Each reader checks every field the package reads from the file -- its presence, its type
(a number is a JSON number, not a bool or a string), that it is finite where it is
computed with -- before anything uses it, and raises
:class:`acld_gym.util.validate.DataFileError` naming the file and the field
(``results.json: algorithms.vrs.per_seed[2].random: expected a number, got 'x'``).
A file that passes renders and resumes without another error.
"""

from __future__ import annotations

import json
import math
import numbers
from pathlib import Path
from typing import Any

from acld_gym.physics.loads import LOAD_CASES as CASES
from acld_gym.util.validate import DataFileError, file_error, shown

__all__ = [
    "DataFileError",
    "read_json",
    "check_results",
    "read_results",
    "check_trial",
    "check_references",
]

#: The statistics of an interquartile mean (:func:`train.core.stats.iqm_with_ci`).
STAT_KEYS = ("iqm", "ci_low", "ci_high")
#: The largest file :func:`read_json` reads (a results table of 25 seeds is ~30 kB).
MAX_BYTES = 64 * 2**20
#: The references every cache holds (the bound is optional: ``--no-bound``).
REFERENCE_NAMES = ("passive", "lqr", "smc", "mpc")


def read_json(path: str | Path, max_bytes: int = MAX_BYTES) -> Any:
    """The JSON value of the file ``path``; :class:`DataFileError` naming it if it is not
    UTF-8 JSON (a truncated file, a binary one, nesting too deep for the parser) or holds
    more than ``max_bytes``. A missing or unreadable file is the ``OSError`` of reading it."""
    with open(path, "rb") as fh:
        data = fh.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise file_error(path, None, f"larger than {max_bytes} bytes: not a file of the benchmark")
    try:
        return json.loads(data.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise file_error(path, None, f"not UTF-8 text (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise file_error(
            path, None, f"not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})"
        ) from None
    except RecursionError:
        raise file_error(path, None, "not valid JSON (nested too deeply)") from None


class _Reader:
    """Checks of the fields of one file; every failure a :class:`DataFileError` naming the
    file and the field's dotted place in it."""

    def __init__(self, path):
        self.path = path

    def fail(self, field: str, message: str):
        raise file_error(self.path, field, message)

    def key(self, obj: dict, key: str, field: str, check, *, optional: bool = False):
        """``check(obj[key], name)``; a missing key fails unless ``optional`` (then None)."""
        name = f"{field}.{key}" if field else key
        if key not in obj:
            if optional:
                return None
            self.fail(name, "missing")
        return check(obj[key], name)

    def mapping(self, value, field: str) -> dict:
        if not isinstance(value, dict):
            self.fail(field, f"expected a mapping, got {shown(value, 40)}")
        return value

    def items(self, value, field: str, nonempty: bool = False) -> list:
        if not isinstance(value, list):
            self.fail(field, f"expected a list, got {shown(value, 40)}")
        if nonempty and not value:
            self.fail(field, "expected a non-empty list")
        return value

    def text(self, value, field: str) -> str:
        if not isinstance(value, str):
            self.fail(field, f"expected a string, got {shown(value, 40)}")
        return value

    def flag(self, value, field: str) -> bool:
        if not isinstance(value, bool):
            self.fail(field, f"expected true or false, got {shown(value, 40)}")
        return value

    def integer(self, value, field: str, low: int = 0, high: int | None = None) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(field, f"expected an integer, got {shown(value, 40)}")
        if value < low or (high is not None and value > high):
            self.fail(field, f"expected an integer in [{low}, {high or 'inf'}], got {value}")
        return value

    def real(self, value, field: str, *, nan: bool = False, low: float | None = None) -> float:
        """A JSON number (not a bool), finite unless ``nan`` (a NaN is then allowed: a time
        not recorded), at least ``low``."""
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            self.fail(field, f"expected a number, got {shown(value, 40)}")
        try:
            x = float(value)
        except OverflowError:  # an integer beyond the float range
            x = math.inf
        if not math.isfinite(x) and not (nan and math.isnan(x)):
            self.fail(field, f"expected a finite number, got {shown(value, 40)}")
        if low is not None and value < low:
            self.fail(field, f"expected a number >= {low:g}, got {value}")
        return value

    def real_or_none(self, value, field: str):
        return None if value is None else self.real(value, field)

    def text_or_none(self, value, field: str):
        return None if value is None else self.text(value, field)

    def stat(self, value, field: str) -> dict:
        """An IQM with its interval, ``{iqm, ci_low, ci_high}`` (finite numbers)."""
        value = self.mapping(value, field)
        for k in STAT_KEYS:
            self.key(value, k, field, self.real)
        return value

    def stat_or_none(self, value, field: str):
        return None if value is None else self.stat(value, field)

    def cases(self, value, field: str, check) -> dict:
        """A mapping with every case of :data:`train.core.evaluate.CASES` (as strings)."""
        value = self.mapping(value, field)
        for c in CASES:
            self.key(value, str(c), field, check)
        return value

    def each(self, value, field: str, check) -> dict:
        """A mapping whose every value passes ``check``."""
        value = self.mapping(value, field)
        for k, v in value.items():
            check(v, f"{field}.{k}")
        return value


def _check_algorithm(r: _Reader, a, field: str, goals: list | None) -> dict:
    """One algorithm's entry of a results table (:func:`train.core.report.summarize`)."""
    a = r.mapping(a, field)
    r.key(a, "algo", field, r.text)
    r.key(a, "budget", field, lambda v, f: r.integer(v, f, 1))
    r.key(a, "restarts", field, lambda v, f: r.integer(v, f, 1), optional=True)
    above = a.get("restart_above")
    if above is not None and not isinstance(above, str):
        r.real(above, f"{field}.restart_above")
    r.key(a, "seeds", field, r.items)
    r.key(a, "ise_rel_lqr", field, lambda v, f: r.cases(v, f, r.stat))
    r.key(a, "validation_cost", field, r.stat_or_none, optional=True)
    got = r.key(a, "goals", field, lambda v, f: r.each(v, f, r.flag))
    if goals is not None and list(got) != goals:
        r.fail(f"{field}.goals", f"expected the goals {goals}, got {list(got)}")
    for key in ("train_seconds", "train_cpu_seconds"):
        nan = key == "train_cpu_seconds"  # NaN: not recorded (old trials)
        t = r.key(a, key, field, r.mapping)
        for k in ("iqm", "max"):
            r.key(t, k, f"{field}.{key}", lambda v, f, nan=nan: r.real(v, f, nan=nan))
    per_seed = r.key(a, "per_seed", field, lambda v, f: r.items(v, f, nonempty=True))
    for i, s in enumerate(per_seed):
        where = f"{field}.per_seed[{i}]"
        s = r.cases(s, where, r.real)
        r.key(s, "seed", where, r.integer)
        r.key(s, "train_seconds", where, r.real)
        r.key(s, "train_cpu_seconds", where, lambda v, f: r.real(v, f, nan=True))
        r.key(s, "runs", where, lambda v, f: r.integer(v, f, 1), optional=not above)
        r.key(s, "validation_cost", where, r.real_or_none, optional=True)
    curve = r.key(a, "curve", field, r.items)
    for i, p in enumerate(curve):
        where = f"{field}.curve[{i}]"
        p = r.cases(p, where, r.stat)
        r.key(p, "steps", where, lambda v, f: r.real(v, f, low=0))
    return a


def check_results(summary, path: str | Path = "results.json") -> dict:
    """``summary`` (a parsed ``results.json`` of ``python -m train.benchmark``) if it holds
    every field :func:`train.core.report.markdown`, :func:`~train.core.report.headline`
    and :func:`~train.core.report.curves_figure` read, of the type they need; else
    :class:`DataFileError` naming ``path`` and the field."""
    r = _Reader(path)
    s = r.mapping(summary, "")
    r.key(s, "env_id", "", r.text)
    episodes = r.key(s, "episodes", "", r.mapping)
    r.key(episodes, "random", "episodes", r.items)
    algos = r.key(s, "algorithms", "", r.mapping)
    if not algos:
        r.fail("algorithms", "expected at least one algorithm")
    goals = None
    for name, a in algos.items():
        a = _check_algorithm(r, a, f"algorithms.{name}", goals)
        goals = list(a["goals"]) if goals is None else goals
    r.key(s, "references", "", lambda v, f: r.each(v, f, lambda x, g: r.cases(x, g, r.real)))
    r.key(
        s,
        "reference_validation_cost",
        "",
        lambda v, f: r.each(v, f, r.real_or_none),
        optional=True,
    )
    r.key(s, "command", "", r.text_or_none, optional=True)
    r.key(s, "wall_seconds", "", r.real_or_none, optional=True)
    return s


def read_results(path: str | Path) -> dict:
    """The checked results table of the file ``path`` (:func:`read_json`,
    :func:`check_results`)."""
    return check_results(read_json(path), path)


def check_trial(rec, path: str | Path) -> dict:
    """``rec`` (a parsed trial record, :func:`train.core.trials.run_trial`) if it holds
    every field the benchmark's summary and a resumed run read; else
    :class:`DataFileError` naming ``path`` and the field."""
    r = _Reader(path)
    rec = r.mapping(rec, "")
    for key in ("name", "algo", "env_id", "command"):
        r.key(rec, key, "", r.text)
    r.key(rec, "seed", "", r.integer)
    r.key(rec, "random_episodes", "", lambda v, f: r.integer(v, f, 1, 20))
    r.key(rec, "config", "", r.mapping)
    r.key(rec, "budget", "", lambda v, f: r.integer(v, f, 1))
    r.key(rec, "steps", "", r.integer)
    r.key(rec, "train_seconds", "", lambda v, f: r.real(v, f, low=0))
    r.key(rec, "train_cpu_seconds", "", lambda v, f: r.real(v, f, nan=True), optional=True)
    r.key(rec, "wall_seconds", "", lambda v, f: r.real(v, f, low=0))
    r.key(rec, "final_ise", "", lambda v, f: r.cases(v, f, r.real))
    r.key(rec, "validation_cost", "", r.real_or_none, optional=True)
    curve = r.key(rec, "curve", "", lambda v, f: r.items(v, f, nonempty=True))
    for i, p in enumerate(curve):
        p = r.mapping(p, f"curve[{i}]")
        r.key(p, "steps", f"curve[{i}]", r.integer)
        r.key(p, "ise", f"curve[{i}]", lambda v, f: r.cases(v, f, r.real))
    record = r.key(rec, "record", "", r.mapping)
    restarts = r.key(record, "restarts", "record", r.mapping, optional=True)
    if restarts is not None:
        r.key(restarts, "runs", "record.restarts", r.items, optional=True)
    return rec


def check_references(data, path: str | Path, bound: bool = True) -> dict:
    """``data`` (a parsed references cache, :func:`train.core.evaluate.references`) if it
    holds every reference's ISE per case (LQR's positive: the tables divide by it), the
    bound's with ``bound``, and the validation costs; else :class:`DataFileError` naming
    ``path`` and the field. The payload only: the record's header (format, kind, key) is
    the cache's to check (:mod:`baselines.evaluation.cache`)."""
    r = _Reader(path)
    data = r.mapping(data, "")
    r.key(data, "env_id", "", r.text)
    seeds = lambda v, f: [r.integer(x, f"{f}[{i}]") for i, x in enumerate(r.items(v, f))]  # noqa: E731
    r.key(data, "episodes", "", lambda v, f: r.cases(v, f, seeds))
    for name in REFERENCE_NAMES + (("bound",) if bound else ()):
        r.key(data, name, "", lambda v, f: r.cases(v, f, r.real))
    for c in CASES:
        if not data["lqr"][str(c)] > 0:
            r.fail(f"lqr.{c}", f"expected a positive ISE, got {data['lqr'][str(c)]}")
    r.key(data, "validation_cost", "", lambda v, f: r.each(v, f, r.real))
    return data
