"""The leaderboard page and the README's block, generated from ``results/<env id>.json`` only.

:func:`page` writes one section per level (every id of
:data:`acld_gym.envs.presets.PRESETS`, "not run yet" where a level has no file): a table of
every reference and algorithm, best score first, with score v2 and its interval, ISE
relative to the thesis LQR on cases 1, 2, 3 and the random loads, the effort after settling
and the training time per seed; the three marks named (the engineer's best design, the
plant oracle, the clairvoyant bound); the goal line (does each algorithm's IQM reach the
best engineer's score minus :data:`GOAL_MARGIN`, and how many seeds beat the thesis LQR and
SMC on cases 1, 2 and the random loads); a table per seed; the machine and the commands
that produced the data (the README's compact table: :mod:`train.leaderboard.readme`).
Nothing is computed beyond reading and comparing the data's
numbers; every number has a fixed format, so the same data give the same bytes.
"""

from __future__ import annotations

from pathlib import Path

from acld_gym.envs.presets import PRESETS
from acld_gym.test_sets import TEST_SETS
from acld_gym.util.validate import file_error

from .schema import CASES, EFFORT_CASES, read_level

__all__ = [
    "COMMAND",
    "GOAL_MARGIN",
    "GOAL_CASES",
    "read_levels",
    "marks",
    "beats",
    "goal_lines",
    "section",
    "page",
]

#: The command that regenerates the page and the README block.
COMMAND = "acld-gym leaderboard render"
#: The mark an algorithm reaches on a level: its IQM at least the best engineer's score minus this.
GOAL_MARGIN = 0.02
#: The cases on which a seed must beat the thesis LQR and SMC (ISE below both).
GOAL_CASES = ("1", "2", "random")
ENGINEER = "engineer's design"
ORACLE = "plant oracle"


def read_levels(results: str | Path) -> dict[str, dict]:
    """``{env id: level}`` of every ``results/<env id>.json`` of a registered id (each
    checked: :func:`train.leaderboard.schema.read_level`). The folder's other files are not
    the leaderboard's: ``make run`` writes its own (``baselines.json``, ``compare.json``,
    ``table2.json``, ...) into ``results/`` too."""
    folder = Path(results)
    if not folder.is_dir():
        raise file_error(folder, None, "not a folder of results (results/<env id>.json)")
    levels = {}
    for env_id in sorted(PRESETS):
        path = folder / f"{env_id}.json"
        if path.is_file():
            levels[env_id] = read_level(path)
    return levels


def _f(x, fmt: str = ".3f") -> str:
    return "-" if x is None else format(x, fmt)


def _score(s: dict) -> str:
    return f"{s['iqm']:.3f} [{s['ci_low']:.3f}, {s['ci_high']:.3f}]"


def _cells(ise: dict, effort: dict, iqm: bool = False) -> list[str]:
    """ISE / LQR per case, V rms and time at the limit after settling per case."""
    get = (lambda v: v["iqm"]) if iqm else (lambda v: v)
    out = [_f(get(ise[c])) for c in CASES]
    out += [_f(get(effort[c]["settled_rms_voltage_V"]), ".1f") for c in EFFORT_CASES]
    out += [_f(100 * get(effort[c]["settled_limit_fraction"]), ".1f") for c in EFFORT_CASES]
    return out


def marks(level: dict) -> dict:
    """``{"engineer": (name, entry) or None, "oracle": ..., "bound": ...}`` of a level's
    references: the engineer's best design (highest score), the plant oracle, the bound."""
    refs = (level["references"] or {}).get("policies", {})
    eng = sorted(
        ((n, e) for n, e in refs.items() if e["kind"] == ENGINEER),
        key=lambda ne: (-ne[1]["score"]["iqm"], ne[0]),
    )
    oracle = sorted((n, e) for n, e in refs.items() if e["kind"] == ORACLE)
    return {
        "engineer": eng[0] if eng else None,
        "oracle": oracle[0] if oracle else None,
        "bound": ("bound", refs["bound"]) if "bound" in refs else None,
    }


HEAD = (
    "| policy | what it is | score v2 [95 % CI] | ISE / LQR case 1 | case 2 | case 3 | random "
    "| V rms settled [V] case 1 | case 2 | at limit settled [%] case 1 | case 2 "
    "| training per seed [s] (IQM; longest) |\n" + "|---" * 12 + "|"
)


def _rows(level: dict) -> list[str]:
    """The level's table rows, best score first (references and each algorithm's IQM)."""
    rows = []
    for name, e in (level["references"] or {}).get("policies", {}).items():
        cells = [f"`{name}`", e["kind"], _score(e["score"]), *_cells(e["ise_rel_lqr"], e["effort"])]
        rows.append((-e["score"]["iqm"], name, cells + ["-"]))
    for name, a in level["agents"].items():
        q = a["iqm"]
        longest = max(s["train_seconds"] for s in a["seeds"])
        what = f"{a['algo']}, {len(a['seeds'])} seeds (IQM)"
        cells = [
            f"`{name}`",
            what,
            _score(q["score"]),
            *_cells(q["ise_rel_lqr"], q["effort"], True),
        ]
        rows.append(
            (-q["score"]["iqm"], name, cells + [f"{q['train_seconds']['iqm']:.0f}; {longest:.0f}"])
        )
    return ["| " + " | ".join(cells) + " |" for _, _, cells in sorted(rows)]


def _seed_rows(level: dict) -> list[str]:
    out = []
    for name, a in sorted(level["agents"].items()):
        for s in sorted(a["seeds"], key=lambda s: s["seed"]):
            retries = f" ({'; '.join(s['retries'])})" if s["retries"] else ""
            cells = [
                f"`{name}`",
                str(s["seed"]),
                _score(s["score"]),
                *_cells(s["ise_rel_lqr"], s["effort"]),
            ]
            cells += [
                f"{s['train_seconds']:.0f}",
                _f(s["train_cpu_seconds"], ".0f"),
                f"{s['runs']}{retries}",
            ]
            out.append("| " + " | ".join(cells) + " |")
    return out


SEED_HEAD = (
    "| algorithm | seed | score v2 [95 % CI] | ISE / LQR case 1 | case 2 | case 3 | random "
    "| V rms settled [V] case 1 | case 2 | at limit settled [%] case 1 | case 2 "
    "| training wall [s] | CPU [s] | runs (retries) |\n" + "|---" * 14 + "|"
)


def beats(entry: dict, smc: dict | None) -> list[str] | None:
    """The :data:`GOAL_CASES` on which ``entry`` (a seed, a run: its ``ise_rel_lqr``) does
    not beat the thesis LQR and SMC (``smc``: SMC's ``ise_rel_lqr``); an empty list where it
    beats both on all of them, None without the level's SMC."""
    if smc is None:
        return None
    rel = entry["ise_rel_lqr"]
    return [c for c in GOAL_CASES if not rel[c] < min(1.0, smc[c])]


def goal_lines(level: dict) -> list[str]:
    """Per algorithm: does its IQM reach the best engineer's score minus
    :data:`GOAL_MARGIN`; how many seeds beat the thesis LQR and SMC on cases 1, 2, random."""
    eng = marks(level)["engineer"]
    smc = (level["references"] or {}).get("policies", {}).get("smc")
    if eng is None or not level["agents"]:
        return []
    target = eng[1]["score"]["iqm"] - GOAL_MARGIN
    out = [
        f"Goal: an algorithm's IQM at least the best engineer's score minus "
        f"{GOAL_MARGIN}, {target:.3f}:"
    ]
    for name, a in sorted(level["agents"].items()):
        got = a["iqm"]["score"]["iqm"]
        verdict = "reaches it" if got >= target else f"does not reach it ({got - target:+.3f})"
        line = f"- `{name}`: IQM {got:.3f}, {verdict}"
        if smc is not None:
            beat = sum(beats(s, smc["ise_rel_lqr"]) == [] for s in a["seeds"])
            line += (
                f"; {beat} of {len(a['seeds'])} seeds beat the thesis LQR and SMC on "
                "cases 1, 2 and random"
            )
        out.append(line + ".")
    return out


def _reduced(env_id: str, level: dict) -> list[str]:
    """Which scores are on fewer episodes than the level's published test set."""
    full = len(TEST_SETS[env_id].seeds)
    refs = (level["references"] or {}).get("policies", {})
    short = {n: e["score"]["n_episodes"] for n, e in refs.items()}
    for name, a in level["agents"].items():
        short.update({f"{name} s{s['seed']}": s["score"]["n_episodes"] for s in a["seeds"]})
    short = {n: k for n, k in short.items() if k < full}
    if not short:
        return []
    names = ", ".join(f"`{n}` ({k})" for n, k in sorted(short.items()))
    return [
        f"Reduced run: {names} scored on fewer than the {full} episodes of the test set "
        "(the first N): not the published score.",
        "",
    ]


def _provenance(what: str, p: dict) -> str:
    commit = p["git_commit"][:10] if p["git_commit"] else "no git commit"
    first, *rest = p["commands"]
    cmds = f"`{first}`" + (", of " + "; ".join(f"`{c}`" for c in rest) if rest else "")
    return (
        f"- {what}: {cmds} (acld-gym {p['acld_gym']}, {commit}, {p['date']}, "
        f"{p['machine']['cpu']}, {p['machine']['cores']} cores)"
    )


def section(env_id: str, level: dict | None) -> list[str]:
    """The page's section of one level."""
    out = [f"## {env_id}", ""]
    if level is None or (level["references"] is None and not level["agents"]):
        return out + [f"Not run yet: no `results/{env_id}.json`.", ""]
    m = marks(level)
    named = {
        "engineer": "the engineer's best design",
        "oracle": "the plant oracle",
        "bound": "the clairvoyant bound",
    }
    said = [f"{named[k]} `{v[0]}` {_score(v[1]['score'])}" for k, v in m.items() if v is not None]
    if said:
        out += ["Marks: " + "; ".join(said) + ".", ""]
    out += _reduced(env_id, level) + [HEAD, *_rows(level), ""]
    out += goal_lines(level) + ([""] if goal_lines(level) else [])
    if level["agents"]:
        out += ["Every seed:", "", SEED_HEAD, *_seed_rows(level), ""]
    out += ["Produced by:", ""]
    if level["references"] is not None:
        out.append(_provenance("references", level["references"]["provenance"]))
    for name, a in sorted(level["agents"].items()):
        out.append(_provenance(f"`{name}` (from `{a['benchmark']}`)", a["provenance"]))
    return out + [""]


INTRO = f"""# Leaderboard

Every reference and trained agent of each level, generated from the committed data
(`results/<env id>.json`, one file per level) by `{COMMAND}`; do not edit this page by
hand (`{COMMAND} --check` fails on any difference, and the tests run it). Data are
collected with `acld-gym leaderboard collect --env-id ID --references` (the
references of `acld-gym evaluate`) and `acld-gym leaderboard collect --env-id ID
--benchmark DIR` (the agents of an `acld-gym benchmark` folder); each is the `python -m`
module of its command (`python -m train.leaderboard`, `python -m baselines.evaluate`,
`python -m train.benchmark`), the form the recorded commands below keep.

- **score v2**: on the level's test set of random loads, the interquartile mean of
  (ISE_passive - ISE) / (ISE_passive - ISE_bound), passive 0 and the clairvoyant bound 1,
  with its 95 % bootstrap interval ([baselines and the bound](baselines.md)); for an
  algorithm, the IQM over its seeds' scores with a 95 % stratified-bootstrap interval.
- **ISE / LQR**: the mean ISE relative to the thesis's LQR on thesis cases 1, 2, 3 (seed 0)
  and the 20 held-out random loads (below 1: better than the thesis LQR).
- **Effort after settling** (from 0.5 s after the load's last edge): the RMS voltage and
  the share of periods at the 120 V limit, on cases 1 and 2.
- **Training per seed**: the training wall time (evaluations excluded) of each seed.
"""


def page(levels: dict[str, dict]) -> str:
    """The whole page ``docs/leaderboard.md`` of ``levels`` (``{env id: level}``)."""
    lines = [INTRO]
    for env_id in PRESETS:
        lines += section(env_id, levels.get(env_id))
    return "\n".join(lines).rstrip("\n") + "\n"
