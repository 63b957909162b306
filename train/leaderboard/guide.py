"""The guide's measured runs: each script of docs/any-library.md run by its own command line
on a seed, the score it prints kept as data (``results/guide/runs.json``), and the page's
tables generated from that file beside each level's engineer (``results/<env id>.json``).

``python -m train.leaderboard guide-run -- COMMAND ...`` runs the command of a guide script
(:data:`CLIENTS`: ``docs/examples/sb3_ppo.py``, ``docs/examples/sb3_sac.py`` or CleanRL's
``ppo_continuous_action.py`` patched with ``docs/examples/cleanrl_ppo.diff``), shows its
output as it goes, times it, reads the score line it prints last
(:class:`train.scoring.PolicyScore`'s ``str``) and merges one record into the file,
replacing a record of the same client, level, seed and budget.
``python -m train.leaderboard render`` writes the page's block (between
:data:`train.leaderboard.guide_page.START` and :data:`train.leaderboard.guide_page.END`)
from the file alone.

The file (:data:`FORMAT` 1) is ``{"format": 1, "runs": [RUN, ...]}``, a run::

    {"client": "SB3 PPO", "command": "python docs/examples/sb3_ppo.py ACLDBeam-v1 --seed 101",
     "env_id": str, "seed": int, "timesteps": int, "score": SCORE,
     "ise_rel_lqr": {"1": x, "2": x, "3": x, "random": x}, "wall_seconds": float,
     "load": [1-min load average at the start, at the end], "provenance": PROV}

(``SCORE`` and ``PROV`` as in :mod:`train.leaderboard.schema`). Nothing read from the file
is executed; a command is only ever run from the command line.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import os
import shlex
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from acld_gym.envs.presets import PRESETS, check_env_id
from acld_gym.test_sets import evaluation_set
from acld_gym.util.atomic import write_json

from ..core.records import read_json
from ..scoring import SCORE_LINE
from .schema import CASES, _Level

__all__ = [
    "FORMAT",
    "CLIENTS",
    "GUIDE_FILE",
    "Client",
    "client_order",
    "parse_command",
    "parse_score",
    "record",
    "guide_run",
    "read_runs",
    "merge_run",
]

#: Version of the file layout (module docstring).
FORMAT = 1
#: The file, relative to the results folder.
GUIDE_FILE = Path("guide") / "runs.json"
#: The largest file read.
MAX_BYTES = 4 * 2**20
ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Client:
    """A guide script: its label, the option of its budget, its defaults (budget, seed) and
    whether the level is its first positional argument (else ``--env-id``)."""

    label: str
    budget_option: str
    budget: int
    seed: int
    positional_env: bool


#: The guide's scripts by file name.
CLIENTS = {
    "sb3_ppo.py": Client("SB3 PPO", "--timesteps", 2_000_000, 0, True),
    "sb3_sac.py": Client("SB3 SAC", "--timesteps", 300_000, 0, True),
    "ppo_continuous_action.py": Client("CleanRL PPO", "--total-timesteps", 1_000_000, 1, False),
}


def parse_command(argv: list[str]) -> tuple[Client, dict]:
    """The client of a guide script's command line and what it runs: ``{"env_id", "seed",
    "timesteps", "command"}`` (the command with the interpreter as ``python`` and a script
    of this checkout relative to it). ``ValueError`` naming what is wrong."""
    at = [i for i, a in enumerate(argv) if Path(a).name in CLIENTS]
    if not at:
        raise ValueError(f"COMMAND: expected a guide script ({', '.join(CLIENTS)}), got {argv}")
    i = at[0]
    client = CLIENTS[Path(argv[i]).name]
    p = argparse.ArgumentParser(add_help=False, exit_on_error=False)
    if client.positional_env:
        p.add_argument("env_id", nargs="?", default="ACLDBeam-v1")
    else:
        p.add_argument("--env-id", dest="env_id", default="ACLDBeam-v1")
    p.add_argument(client.budget_option, dest="timesteps", type=int, default=client.budget)
    p.add_argument("--seed", type=int, default=client.seed)
    try:
        args, _ = p.parse_known_args(argv[i + 1 :])
    except argparse.ArgumentError as exc:
        raise ValueError(f"COMMAND: {exc}") from None
    script = Path(argv[i])
    if script.is_absolute() and script.resolve().is_relative_to(ROOT):
        script = script.resolve().relative_to(ROOT)
    shown = ["python" if Path(a).name.startswith("python") else a for a in argv[:i]]
    what = {
        "env_id": check_env_id(args.env_id, "COMMAND's level"),
        "seed": args.seed,
        "timesteps": args.timesteps,
        "command": shlex.join([*shown, str(script), *argv[i + 1 :]]),
    }
    return client, what


def parse_score(output: str) -> dict:
    """The last score line of a script's output: ``{"env_id", "score": SCORE,
    "ise_rel_lqr"}``; ``ValueError`` if there is none."""
    for line in reversed(output.strip().splitlines()):
        m = SCORE_LINE.match(line.strip())
        if m:
            break
    else:
        raise ValueError("the command printed no score line (score v2 on ...; ISE / ...)")
    env_id = check_env_id(m["id"], "the score line's level")
    full = len(evaluation_set(env_id).seeds)
    score = {
        "version": int(m["version"]),
        "iqm": float(m["iqm"]),
        "ci_low": float(m["lo"]),
        "ci_high": float(m["hi"]),
        "n_episodes": int(m["n"]) if m["n"] else full,
        "test_set": f"{env_id}/{m['set']}",
    }
    ise = {c: float(m[k]) for c, k in zip(CASES, ("c1", "c2", "c3", "cr"), strict=True)}
    return {"env_id": env_id, "score": score, "ise_rel_lqr": ise}


def record(argv: list[str], output: str, wall: float, load: list[float]) -> dict:
    """One run's record (module docstring) from its command line, its output and its wall
    time; ``ValueError`` if the output's level is not the command's."""
    from .collect import provenance

    client, what = parse_command(argv)
    got = parse_score(output)
    if got["env_id"] != what["env_id"]:
        raise ValueError(
            f"the command runs {what['env_id']} but its score line is on {got['env_id']}"
        )
    return {
        "client": client.label,
        **what,
        "score": got["score"],
        "ise_rel_lqr": got["ise_rel_lqr"],
        "wall_seconds": round(wall, 1),
        "load": [round(x, 2) for x in load],
        "provenance": provenance([what["command"]]),
    }


def _load() -> float:
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0


def guide_run(argv: list[str], results: str | Path, echo=None) -> dict:
    """Run ``argv`` (checked first), echo its output, and merge its record into the
    results folder's :data:`GUIDE_FILE` (``echo``: a text stream, default ``sys.stdout``);
    ``RuntimeError`` if it fails (nothing written)."""
    echo = sys.stdout if echo is None else echo
    parse_command(argv)  # a command that is no guide script is refused before it runs
    path = Path(results) / GUIDE_FILE
    if path.is_file():
        read_runs(path)  # a damaged file is refused before the run, not after it
    tail: collections.deque[str] = collections.deque(maxlen=200)
    start, t0 = _load(), time.perf_counter()
    with subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1
    ) as proc:
        for line in proc.stdout:
            echo.write(line)
            tail.append(line)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"the command exited with {proc.returncode}: nothing recorded")
    rec = record(argv, "".join(tail), wall, [start, _load()])
    path.parent.mkdir(parents=True, exist_ok=True)
    with _locked(path.parent):  # runs at once: each merges into what the others wrote
        runs = read_runs(path) if path.is_file() else []
        write_json(path, {"format": FORMAT, "runs": merge_run(runs, rec)})
    return rec


@contextlib.contextmanager
def _locked(folder: Path):
    """An exclusive lock on ``folder`` (POSIX ``flock``; elsewhere none)."""
    try:
        import fcntl
    except ImportError:  # Windows: one run at a time
        yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def client_order(label: str) -> int:
    """Where a client's runs go: the order of :data:`CLIENTS`."""
    return [c.label for c in CLIENTS.values()].index(label)


def _key(run: dict) -> tuple:
    return (run["client"], run["env_id"], run["seed"], run["timesteps"])


def merge_run(runs: list[dict], new: dict) -> list[dict]:
    """``runs`` with ``new`` replacing the run of its client, level, seed and budget,
    sorted by client, level and seed."""
    kept = [r for r in runs if _key(r) != _key(new)]
    levels = list(PRESETS)
    return sorted(
        [*kept, new],
        key=lambda r: (
            client_order(r["client"]),
            levels.index(r["env_id"]),
            r["timesteps"],
            r["seed"],
        ),
    )


class _Guide(_Level):
    def run(self, value, field: str) -> dict:
        value = self.mapping(value, field)
        label = self.key(value, "client", field, self.text)
        if label not in {c.label for c in CLIENTS.values()}:
            self.fail(f"{field}.client", f"expected one of the guide's clients, got {label!r}")
        self.key(value, "command", field, self.text)
        env_id = self.key(value, "env_id", field, self.text)
        try:
            check_env_id(env_id, "env_id")
        except ValueError as exc:
            self.fail(f"{field}.env_id", str(exc).removeprefix("env_id "))
        self.key(value, "seed", field, lambda v, f: self.integer(v, f, 0))
        self.key(value, "timesteps", field, lambda v, f: self.integer(v, f, 1))
        self.key(value, "score", field, self.score)
        self.key(value, "ise_rel_lqr", field, lambda v, f: self.cases_of(v, f, self.positive))
        self.key(value, "wall_seconds", field, lambda v, f: self.real(v, f, low=0))
        load = self.key(value, "load", field, self.items)
        for i, x in enumerate(load):
            self.real(x, f"{field}.load[{i}]", low=0)
        self.key(value, "provenance", field, self.provenance)
        return value


def read_runs(path: str | Path) -> list[dict]:
    """The checked runs of a guide file; :class:`acld_gym.util.validate.DataFileError` with
    one line naming the file and the field."""
    r = _Guide(path)
    data = r.mapping(read_json(path, MAX_BYTES), "")
    fmt = r.key(data, "format", "", r.integer)
    if fmt != FORMAT:
        r.fail("format", f"expected {FORMAT}, got {fmt}")
    runs = r.key(data, "runs", "", r.items)
    for i, run in enumerate(runs):
        r.run(run, f"runs[{i}]")
    keys = [_key(run) for run in runs]
    if len(set(keys)) != len(keys):
        r.fail("runs", "expected one run per client, level, seed and budget")
    return runs
