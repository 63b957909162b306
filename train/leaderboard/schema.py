"""The leaderboard's data: one JSON file per level, ``results/<env id>.json``, and its checks.

A file (:data:`FORMAT` 1) is a mapping::

    {"format": 1, "env_id": "ACLDBeam-v1",
     "references": null or {"provenance": PROV, "policies": {name: ENTRY}},
     "agents": {algorithm: {"algo": str, "benchmark": str, "provenance": PROV,
                            "seeds": [SEED, ...],
                            "iqm": {"score": STAT, "ise_rel_lqr": {case: STAT},
                                    "effort": {"1": {measure: STAT}, "2": ...},
                                    "train_seconds": STAT}}}}

* ``ENTRY`` (a reference): ``{"kind": str, "score": SCORE, "ise_rel_lqr": {case: x},
  "effort": {"1": EFFORT, "2": EFFORT}}``;
* ``SEED`` (one trained agent): ``ENTRY`` without ``kind``, with ``seed``, ``steps``,
  ``budget``, ``train_seconds``, ``train_cpu_seconds`` (None: not recorded), ``runs`` and
  ``retries`` (the reasons, from the trial's record);
* ``SCORE``: score v2 on the level's test set, ``{"version", "iqm", "ci_low", "ci_high",
  "n_episodes", "test_set"}`` (:meth:`baselines.evaluation.score.Score.as_dict`'s fields);
* ``case``: ``"1"``, ``"2"``, ``"3"`` (thesis cases, seed 0) and ``"random"`` (the held-out
  random loads); ``ise_rel_lqr``: the mean ISE over the case's episodes divided by the
  thesis LQR's;
* ``EFFORT``: after the tip has settled (:mod:`baselines.analysis.effort`),
  ``{"settled_rms_voltage_V", "settled_limit_fraction"}``;
* ``STAT``: an IQM over the seeds with its 95 % stratified-bootstrap interval,
  ``{"iqm", "ci_low", "ci_high", "n"}`` (:func:`acld_gym.util.stats.iqm_with_ci`);
* ``PROV``: ``{"commands": [str], "acld_gym": str, "git_commit": str or None, "date": str,
  "machine": {"cpu": str, "cores": int}}``.

:func:`check_level` checks every field the renderer reads (presence, JSON type, finite
numbers, nesting at most :data:`MAX_DEPTH`), raising
:class:`acld_gym.util.validate.DataFileError` with one line naming the file and the field.
Nothing read from a file is ever executed or imported: the env id is matched as a plain
string against this package's ids (:func:`acld_gym.envs.presets.check_env_id`).
"""

from __future__ import annotations

from pathlib import Path

from acld_gym.envs.presets import check_env_id
from acld_gym.util.validate import DataFileError, file_error, json_depth

from ..core.records import _Reader, read_json

__all__ = [
    "FORMAT",
    "CASES",
    "EFFORT_CASES",
    "EFFORT_KEYS",
    "MAX_DEPTH",
    "MAX_BYTES",
    "check_level",
    "read_level",
    "empty_level",
]

#: Version of the file layout (module docstring).
FORMAT = 1
#: The cases of the ISE / thesis LQR columns.
CASES = ("1", "2", "3", "random")
#: The cases with a settled window (:func:`baselines.analysis.effort.settled_from`).
EFFORT_CASES = ("1", "2")
#: The effort measures after settling, per case.
EFFORT_KEYS = ("settled_rms_voltage_V", "settled_limit_fraction")
#: The deepest nesting of a valid file is 7 (agents.ppo.seeds[0].effort.1.key).
MAX_DEPTH = 8
#: The largest file read (a level with five algorithms of 20 seeds is ~100 kB).
MAX_BYTES = 4 * 2**20


class _Level(_Reader):
    """The checks of one results file (fields named by their dotted place)."""

    def positive(self, value, field: str) -> float:
        self.real(value, field)
        if not value > 0:
            self.fail(field, f"expected a positive number, got {value}")
        return value

    def score(self, value, field: str) -> dict:
        value = self.mapping(value, field)
        self.key(value, "version", field, lambda v, f: self.integer(v, f, 1))
        for k in ("iqm", "ci_low", "ci_high"):
            self.key(value, k, field, self.real)
        self.key(value, "n_episodes", field, lambda v, f: self.integer(v, f, 1))
        self.key(value, "test_set", field, self.text)
        if not value["ci_low"] <= value["iqm"] <= value["ci_high"]:
            self.fail(field, "expected ci_low <= iqm <= ci_high")
        return value

    def stat(self, value, field: str) -> dict:
        value = super().stat(value, field)
        self.key(value, "n", field, lambda v, f: self.integer(v, f, 1))
        return value

    def cases_of(self, value, field: str, check) -> dict:
        value = self.mapping(value, field)
        for c in CASES:
            self.key(value, c, field, check)
        return value

    def effort(self, value, field: str) -> dict:
        value = self.mapping(value, field)
        for c in EFFORT_CASES:
            e = self.key(value, c, field, self.mapping)
            for k in EFFORT_KEYS:
                self.key(e, k, f"{field}.{c}", lambda v, f: self.real(v, f, low=0))
        return value

    def entry(self, value, field: str) -> dict:
        value = self.mapping(value, field)
        self.key(value, "score", field, self.score)
        self.key(value, "ise_rel_lqr", field, lambda v, f: self.cases_of(v, f, self.positive))
        self.key(value, "effort", field, self.effort)
        return value

    def provenance(self, value, field: str) -> dict:
        value = self.mapping(value, field)
        commands = self.key(value, "commands", field, lambda v, f: self.items(v, f, True))
        for i, c in enumerate(commands):
            self.text(c, f"{field}.commands[{i}]")
        self.key(value, "acld_gym", field, self.text)
        self.key(value, "git_commit", field, self.text_or_none)
        self.key(value, "date", field, self.text)
        machine = self.key(value, "machine", field, self.mapping)
        self.key(machine, "cpu", f"{field}.machine", self.text)
        self.key(machine, "cores", f"{field}.machine", lambda v, f: self.integer(v, f, 1))
        return value

    def seed(self, value, field: str) -> dict:
        value = self.entry(value, field)
        self.key(value, "seed", field, self.integer)
        for k in ("steps", "budget"):
            self.key(value, k, field, self.integer)
        self.key(value, "train_seconds", field, lambda v, f: self.real(v, f, low=0))
        self.key(value, "train_cpu_seconds", field, self.real_or_none)
        self.key(value, "runs", field, lambda v, f: self.integer(v, f, 1))
        retries = self.key(value, "retries", field, self.items)
        for i, r in enumerate(retries):
            self.text(r, f"{field}.retries[{i}]")
        return value

    def algorithm(self, value, field: str) -> dict:
        value = self.mapping(value, field)
        for k in ("algo", "benchmark"):
            self.key(value, k, field, self.text)
        self.key(value, "provenance", field, self.provenance)
        seeds = self.key(value, "seeds", field, lambda v, f: self.items(v, f, True))
        for i, s in enumerate(seeds):
            self.seed(s, f"{field}.seeds[{i}]")
        got = [s["seed"] for s in seeds]
        if len(set(got)) != len(got):
            self.fail(f"{field}.seeds", f"expected distinct seeds, got {got}")
        iqm = self.key(value, "iqm", field, self.mapping)
        self.key(iqm, "score", f"{field}.iqm", self.stat)
        self.key(iqm, "ise_rel_lqr", f"{field}.iqm", lambda v, f: self.cases_of(v, f, self.stat))
        self.key(iqm, "effort", f"{field}.iqm", self.effort_stats)
        self.key(iqm, "train_seconds", f"{field}.iqm", self.stat)
        return value

    def effort_stats(self, value, field: str) -> dict:
        value = self.mapping(value, field)
        for c in EFFORT_CASES:
            e = self.key(value, c, field, self.mapping)
            for k in EFFORT_KEYS:
                self.key(e, k, f"{field}.{c}", self.stat)
        return value


def check_level(data, path: str | Path) -> dict:
    """``data`` (a parsed results file) if it is a level's results of the form of the
    module docstring; else :class:`DataFileError` naming ``path`` and the field. A file
    named ``<env id>.json`` must hold that id."""
    if json_depth(data, MAX_DEPTH) > MAX_DEPTH:
        raise file_error(path, None, f"nested deeper than {MAX_DEPTH} levels")
    r = _Level(path)
    d = r.mapping(data, "")
    fmt = r.key(d, "format", "", r.integer)
    if fmt != FORMAT:
        r.fail("format", f"expected {FORMAT}, got {fmt}")
    env_id = r.key(d, "env_id", "", r.text)
    try:
        check_env_id(env_id, "env_id")
    except ValueError as exc:
        r.fail("env_id", str(exc).removeprefix("env_id "))
    stem = Path(path).name.removesuffix(".json")
    if Path(path).suffix == ".json" and stem != env_id:
        r.fail("env_id", f"expected {stem!r} (the file's name), got {env_id!r}")
    refs = d.get("references", "missing")
    if refs == "missing":
        r.fail("references", "missing")
    if refs is not None:
        r.key(d, "references", "", r.mapping)
        r.key(refs, "provenance", "references", r.provenance)
        pols = r.key(refs, "policies", "references", r.mapping)
        for name, e in pols.items():
            e = r.entry(e, f"references.policies.{name}")
            r.key(e, "kind", f"references.policies.{name}", r.text)
    agents = r.key(d, "agents", "", r.mapping)
    for name, a in agents.items():
        r.algorithm(a, f"agents.{name}")
    return d


def read_level(path: str | Path) -> dict:
    """The checked results of the file ``path`` (UTF-8 JSON of at most :data:`MAX_BYTES`;
    :func:`check_level`). A missing file is the ``OSError`` of reading it."""
    return check_level(read_json(path, MAX_BYTES), path)


def empty_level(env_id: str) -> dict:
    """A level's results before anything is collected."""
    return {"format": FORMAT, "env_id": check_env_id(env_id), "references": None, "agents": {}}


__all__ += ["DataFileError"]
