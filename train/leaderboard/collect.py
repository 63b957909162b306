"""Collect a level's numbers into ``results/<env id>.json`` (:mod:`train.leaderboard.schema`).

:func:`collect_references` measures every reference and mark of the level
(:func:`baselines.marks.level_references`: what ``python -m baselines.evaluate --env-id ID``
reports, and the clairvoyant bound); :func:`collect_benchmark` the trained agents of a
``python -m train.benchmark --env-id ID --out DIR`` folder (its ``trials/<name>-s<seed>.json``
records and ``agents/<name>-s<seed>/`` folders), per algorithm every seed and the IQM over
the seeds with its 95 % stratified-bootstrap interval. :func:`merge` puts either part into
the level's file without touching the others (the references, each algorithm), and
:func:`write_level` writes it atomically, keys sorted. Every file read is checked first
(:func:`train.core.records.check_trial`, :meth:`train.agent.TrainedAgent.load`,
:func:`train.leaderboard.schema.read_level`): a damaged one is one line naming it, and
nothing is written.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

import acld_gym
from acld_gym.envs.presets import check_env_id
from acld_gym.util.atomic import strict_json, write_json
from acld_gym.util.stats import iqm_with_ci
from acld_gym.util.validate import DataFileError, file_error
from baselines.evaluation.references import make_env
from baselines.evaluation.seeds import evaluation_set
from baselines.marks import level_references, mark_labels

from ..core.records import check_trial, read_json
from ..core.trials import agent_dir
from .measure import agent_entry, reference_entries
from .schema import CASES, EFFORT_CASES, EFFORT_KEYS, check_level, empty_level, read_level

__all__ = [
    "provenance",
    "collect_references",
    "read_trials",
    "collect_benchmark",
    "seed_stats",
    "merge",
    "load_or_empty",
    "write_level",
    "level_path",
]

ROOT = Path(__file__).resolve().parents[2]


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def _git_commit() -> str | None:
    """The checkout's commit (None outside a git checkout or without git)."""
    try:
        done = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "HEAD"],
            capture_output=True,
            text=True,
            timeout=10,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    out = done.stdout.strip()
    return out if done.returncode == 0 and out else None


def provenance(commands: list[str]) -> dict:
    """``PROV`` (:mod:`train.leaderboard.schema`): the commands, this package's version,
    the git commit, the date (UTC) and the machine (CPU model, core count)."""
    return {
        "commands": list(commands),
        "acld_gym": acld_gym.__version__,
        "git_commit": _git_commit(),
        "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "machine": {"cpu": _cpu_model(), "cores": os.cpu_count() or 1},
    }


def collect_references(
    env_id: str,
    command: str,
    episodes: int | None = None,
    policies: dict | None = None,
    quiet: bool = True,
) -> dict:
    """The ``references`` part of a level's file: every reference and mark of ``env_id``
    (``policies``: name -> policy instead, e.g. a subset) and the bound, with
    provenance (``command``: how it was asked for)."""
    env_id = check_env_id(env_id, "--env-id")
    if policies is None:
        probe = make_env(evaluation_set(env_id)).unwrapped
        policies = level_references(probe)
    reduced = "" if episodes is None else f" --score-episodes {episodes}"
    return {
        "provenance": provenance(
            [command, f"python -m baselines.evaluate --env-id {env_id}{reduced}"]
        ),
        "policies": reference_entries(env_id, policies, mark_labels(policies), episodes, quiet),
    }


def read_trials(folder: Path, env_id: str, names=None) -> dict[str, list[dict]]:
    """``{name: [record, ...]}`` (by seed) of the checked trial records in
    ``folder/trials`` of ``env_id`` (``names``: only these configs; each must have one).
    ``DataFileError`` naming the file: a damaged record, or one of another level."""
    files = sorted((folder / "trials").glob("*.json"))
    if not files:
        raise file_error(folder, None, "no trials/*.json: not a python -m train.benchmark folder")
    out: dict[str, list[dict]] = {}
    for f in files:
        rec = check_trial(read_json(f), f)
        if rec["env_id"] != env_id:
            raise file_error(f, "env_id", f"expected {env_id} (--env-id), got {rec['env_id']!r}")
        if names is None or rec["name"] in names:
            out.setdefault(rec["name"], []).append(rec)
    missing = [n for n in names or () if n not in out]
    if missing:
        raise file_error(folder / "trials", None, f"no trial of {missing} (--algos)")
    return {k: sorted(v, key=lambda r: r["seed"]) for k, v in sorted(out.items())}


def _benchmark_commands(folder: Path, records: list[dict]) -> list[str]:
    """The benchmark command of ``folder/results.json`` if it names one, else each trial's."""
    results = folder / "results.json"
    if results.is_file():
        data = read_json(results)
        command = data.get("command") if isinstance(data, dict) else None
        if isinstance(command, str):
            return [command]
    return list(dict.fromkeys(r["command"] for r in records))


def seed_stats(seeds: list[dict]) -> dict:
    """``{"score": STAT, "ise_rel_lqr": {case: STAT}, "effort": {case: {measure: STAT}},
    "train_seconds": STAT}``: the IQM over ``seeds`` (``SEED`` entries) of their scores, of
    each ISE column, of each effort measure and of the training wall time, with 95 %
    stratified-bootstrap intervals (:func:`acld_gym.util.stats.iqm_with_ci`, one task)."""

    def stat(values) -> dict:
        return iqm_with_ci(np.array(values, dtype=float))

    return {
        "score": stat([s["score"]["iqm"] for s in seeds]),
        "ise_rel_lqr": {c: stat([s["ise_rel_lqr"][c] for s in seeds]) for c in CASES},
        "effort": {
            c: {k: stat([s["effort"][c][k] for s in seeds]) for k in EFFORT_KEYS}
            for c in EFFORT_CASES
        },
        "train_seconds": stat([s["train_seconds"] for s in seeds]),
    }


def _agent_seed(folder: Path, rec: dict, env_id: str, episodes: int | None) -> dict:
    from ..agent import TrainedAgent

    where = agent_dir(folder, rec["name"], rec["seed"])
    try:
        agent = TrainedAgent.load(where)
    except ValueError as exc:  # AgentFileError: names the file and the field
        raise DataFileError(str(exc)) from None
    got = agent.metadata.get("env", {}).get("id")
    if got != env_id:
        raise file_error(where / "metadata.json", "env.id", f"expected {env_id}, got {got!r}")
    cpu = rec.get("train_cpu_seconds")
    return {
        **agent_entry(agent, env_id, episodes),
        "seed": rec["seed"],
        "steps": rec["steps"],
        "budget": rec["budget"],
        "train_seconds": float(rec["train_seconds"]),
        "train_cpu_seconds": None if cpu is None or not np.isfinite(cpu) else float(cpu),
        "runs": int(rec.get("runs", 1)),
        "retries": [str(r) for r in rec.get("retries", [])],
    }


def collect_benchmark(
    folder: str | Path,
    env_id: str,
    command: str,
    names=None,
    episodes: int | None = None,
    progress=print,
) -> dict:
    """``{name: ALGORITHM}`` (:mod:`train.leaderboard.schema`) of the benchmark
    ``folder``'s algorithms (``names``: only these), every seed scored by
    :func:`train.scoring.score`."""
    folder = Path(folder)
    env_id = check_env_id(env_id, "--env-id")
    out = {}
    for name, records in read_trials(folder, env_id, names).items():
        seeds = []
        for rec in records:
            if progress is not None:
                progress(f"  {name} seed {rec['seed']}: scoring on {env_id}")
            seeds.append(_agent_seed(folder, rec, env_id, episodes))
        out[name] = {
            "algo": records[0]["algo"],
            "benchmark": str(folder),
            "provenance": provenance([command, *_benchmark_commands(folder, records)]),
            "seeds": seeds,
            "iqm": seed_stats(seeds),
        }
    return out


def merge(level: dict, references: dict | None = None, agents: dict | None = None) -> dict:
    """``level`` with its references replaced by ``references`` (if given) and each
    algorithm of ``agents`` replaced (the others kept)."""
    out = dict(level, agents=dict(level["agents"]))
    if references is not None:
        out["references"] = references
    out["agents"].update(agents or {})
    return out


def level_path(results: str | Path, env_id: str) -> Path:
    """``results/<env id>.json``."""
    return Path(results) / f"{check_env_id(env_id, '--env-id')}.json"


def load_or_empty(path: Path, env_id: str) -> dict:
    """The checked level file ``path``, or an empty level if there is none."""
    return read_level(path) if path.exists() else empty_level(env_id)


def write_level(path: Path, level: dict) -> Path:
    """Write ``level`` to ``path`` atomically, keys sorted, NaN as null, after checking that
    it reads back (:func:`train.leaderboard.schema.check_level`)."""
    data = json.loads(json.dumps(strict_json(level), sort_keys=True))
    check_level(data, path)
    return write_json(path, data)
