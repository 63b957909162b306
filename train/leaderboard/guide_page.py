"""The block of docs/any-library.md generated from the guide's runs
(:mod:`train.leaderboard.guide`) and the levels' references (``results/<env id>.json``),
between :data:`START` and :data:`END`: for each guide script and level, how many seeds beat
the thesis LQR and SMC on cases 1, 2 and the random loads, beside the level's engineer; then
every run with its score, ISE relative to the thesis LQR, wall time, the machine's load and
its command. Nothing is computed beyond comparing the data's numbers.
"""

from __future__ import annotations

from acld_gym.envs.presets import PRESETS
from acld_gym.test_sets import TEST_SETS

from .guide import GUIDE_FILE, client_order
from .render import COMMAND, beats, marks

__all__ = ["START", "END", "guide_block"]

START = "<!-- guide-runs:start -->"
END = "<!-- guide-runs:end -->"


def _steps(n: int) -> str:
    if n % 1_000_000 == 0:
        return f"{n // 1_000_000}M"
    return f"{n // 1000}k" if n % 1000 == 0 else str(n)


def _policies(level: dict | None) -> dict:
    """A level's reference entries by name (none without the level's file)."""
    return ((level or {}).get("references") or {}).get("policies", {})


def _smc(level: dict | None) -> dict | None:
    refs = _policies(level)
    return refs["smc"]["ise_rel_lqr"] if "smc" in refs else None


def _reduced(run: dict) -> bool:
    return run["score"]["n_episodes"] < len(TEST_SETS[run["env_id"]].seeds)


def _summary(runs: list[dict], levels: dict) -> list[str]:
    heads = ["client, budget", *(f"`{e}`" for e in PRESETS)]
    rows = ["| " + " | ".join(heads) + " |", "|---" * len(heads) + "|"]
    eng = ["the level's engineer (best design)"]
    lqr = ["the thesis LQR"]
    for env_id in PRESETS:
        level = levels.get(env_id)
        m = marks(level) if level else {"engineer": None}
        e = m["engineer"]
        eng.append("-" if e is None else f"{e[1]['score']['iqm']:.3f} (`{e[0]}`)")
        refs = _policies(level)
        lqr.append(f"{refs['lqr']['score']['iqm']:.3f}" if "lqr" in refs else "-")
    rows += ["| " + " | ".join(eng) + " |", "| " + " | ".join(lqr) + " |"]
    budgets = sorted(
        {(r["client"], r["timesteps"]) for r in runs}, key=lambda k: (client_order(k[0]), k[1])
    )
    for label, budget in budgets:
        cells = [f"{label}, {_steps(budget)} steps"]
        for env_id in PRESETS:
            mine = [
                r
                for r in runs
                if (r["client"], r["timesteps"], r["env_id"]) == (label, budget, env_id)
            ]
            smc = _smc(levels.get(env_id))
            if not mine:
                cells.append("not run")
                continue
            scores = sorted(r["score"]["iqm"] for r in mine)
            span = f"{scores[0]:.3f}" + (f" to {scores[-1]:.3f}" if len(scores) > 1 else "")
            won = "-" if smc is None else str(sum(beats(r, smc) == [] for r in mine))
            short = " (reduced)" if any(_reduced(r) for r in mine) else ""
            cells.append(f"{won} of {len(mine)} seeds; score {span}{short}")
        rows.append("| " + " | ".join(cells) + " |")
    return rows


RUN_HEAD = (
    "| client, budget | level | seed | score v2 [95 % CI] | ISE / LQR case 1 | case 2 | case 3 "
    "| random | beats the thesis LQR and SMC | wall [min] | load | command |\n" + "|---" * 12 + "|"
)


def _run_row(run: dict, levels: dict) -> str:
    s = run["score"]
    score = f"{s['iqm']:.3f} [{s['ci_low']:.3f}, {s['ci_high']:.3f}]"
    if _reduced(run):
        score += f" (first {s['n_episodes']})"
    missed = beats(run, _smc(levels.get(run["env_id"])))
    verdict = "-" if missed is None else ("yes" if not missed else f"no ({', '.join(missed)})")
    load = ", ".join(f"{x:.1f}" for x in run["load"]) or "-"
    cells = [
        f"{run['client']}, {_steps(run['timesteps'])}",
        f"`{run['env_id']}`",
        str(run["seed"]),
        score,
        *(f"{run['ise_rel_lqr'][c]:.3f}" for c in ("1", "2", "3", "random")),
        verdict,
        f"{run['wall_seconds'] / 60:.1f}",
        load,
        f"`{run['command']}`",
    ]
    return "| " + " | ".join(cells) + " |"


def _machines(runs: list[dict]) -> list[str]:
    seen = sorted(
        {
            (
                r["provenance"]["machine"]["cpu"],
                r["provenance"]["machine"]["cores"],
                r["provenance"]["acld_gym"],
                (r["provenance"]["git_commit"] or "no commit")[:7],
            )
            for r in runs
        }
    )
    dates = sorted(r["provenance"]["date"][:10] for r in runs)
    return [
        f"- {cpu}, {cores} cores; acld-gym {version} at commit {commit}"
        for cpu, cores, version, commit in seen
    ] + [f"- dates: {dates[0]} to {dates[-1]}"]


def guide_block(runs: list[dict], levels: dict[str, dict]) -> str:
    """The block, markers included (no runs: the block says so)."""
    lead = (
        f"Generated from `results/{GUIDE_FILE.as_posix()}` and `results/<env id>.json` by "
        f"`{COMMAND}`; each run measured by `acld-gym leaderboard guide-run -- "
        "COMMAND` (its command in the last column). ISE / LQR: on cases 1, 2, 3 (seed 0) and "
        "the held-out random loads; a run beats the thesis LQR and SMC where its ISE is below "
        "both on cases 1, 2 and the random loads. Wall time: the command's, training and the "
        "full score; load: the machine's 1-minute load average at its start and end."
    )
    if not runs:
        return "\n".join([START, "", lead, "", "No run recorded yet.", "", END])
    body = [START, "", lead, "", *_summary(runs, levels), "", "Every run:", "", RUN_HEAD]
    body += [_run_row(r, levels) for r in runs]
    body += ["", "Measured on:", "", *_machines(runs), "", END]
    return "\n".join(body)
