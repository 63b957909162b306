"""``python -m train.benchmark``: reinforcement learning from scratch on ACLDBeam, no teacher.

Trains every algorithm (one YAML file each under ``train/recipes/``: hyperparameters
and a fixed env-step budget, the same for every seed) with every seed, from random
initialisation, on the env's observation and reward only. Then evaluates each final
policy deterministically through the env (+/-120 V, 1 ms, default Kalman observer):
ISE / ISE_LQR on thesis cases 1, 2, 3 (seed 0) and on the held-out random set
(``acld_gym.test_sets.HELDOUT_SEEDS``). LQR, SMC, MPC and the clairvoyant bound are used
only to normalise and report these numbers.

Writes to ``--out`` (default ``runs/<env id>/benchmark``: runs on different levels never
share a folder), atomically:

* ``results.md`` / ``results.json``: per algorithm the interquartile mean (IQM) over
  seeds with 95 % stratified-bootstrap intervals, the training wall time, the
  checks, and every seed's numbers;
* ``learning_curves.png``: IQM ISE / LQR vs env steps with 95 % bands, and the LQR,
  SMC, MPC and bound levels;
* ``trials/<name>-s<seed>.json`` (one per run) and ``references-<env id>.json``.

A command of several trials runs them through Ray Tune when it is installed
(``--backend ray``: one trial per CPU, local with ``--num-cpus`` or on a cluster with
``--address``), else one after the other (``--backend local``); a single trial (one
config, one seed) runs here, without Ray, unless ``--backend ray`` or ``--address`` asks
for it.

Examples::

    python -m train.benchmark                                  # 5 algorithms x 5 seeds
    python -m train.benchmark --algos vrs --seeds 0 1 2 3 4 --out runs/ACLDBeam-v1/vrs
    python -m train.benchmark --config studies/ablations/ablation_vrs_return.yaml \\
        --seeds 0 1 2 --out runs/ACLDBeam-v1/ablation_vrs_return
    python -m train.benchmark --env-id ACLDBeamLab-v1 --backend ray --num-cpus 2

The recipes run unchanged on every registered id: a recipe's retry threshold is resolved
on the level's own reference (:mod:`train.core.threshold`). While it trains, each trial
says a line per evaluation with its current validation score (``--quiet``: none), the
threshold, and every retry with its reason, which its record keeps (``retries``).

A recipe with several runs per seed (``restarts``: PPO's and SAC's) trains up to
``--cpus-per-trial`` of them at once, in worker processes: the same runs, taken in the
same order, so the same agent, in less wall time. By default such a trial takes every one
of the ``--num-cpus`` and the trials run one after another (``--algos ppo sac --seeds 7``
on 2 CPUs: PPO's seed, then SAC's, each with two runs at once), so a seed's wall time is
its own runs' whatever else the command trains; ``--cpus-per-trial 1`` runs two trials
at a time instead, more seeds per hour and a longer wait for each.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from acld_gym.util.atomic import check_directory, check_writable, write_text, write_texts
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import DataFileError, arg_type, run_main

from .agent_files import check_replaceable
from .cli import MAX_SEED, env_id_arg
from .config import CONFIG_DIR, TrainConfig, config_path, read_config
from .config_checks import check_buildable
from .core.evaluate import DEFAULT_ENV_ID
from .core.records import check_references, check_trial, read_json
from .core.report import markdown, plot_curves, summarize
from .core.trials import (
    DEFAULT_ALGOS,
    agent_dir,
    policy_program,
    ray_available,
    run_trial,
    run_trials,
    trial_path,
)

__all__ = [
    "CONFIG_DIR",
    "DEFAULT_ALGOS",
    "agent_dir",
    "auto_backend",
    "read_config",
    "policy_program",
    "run_trial",
    "run_trials",
    "summarize",
    "markdown",
    "plot_curves",
    "main",
]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog("python -m train.benchmark"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--algos",
        nargs="+",
        default=None,
        metavar="NAME",
        help=f"configs under train/recipes/ (default: {' '.join(DEFAULT_ALGOS)})",
    )
    p.add_argument(
        "--config",
        nargs="+",
        default=(),
        metavar="YAML",
        help="further config files (e.g. the ablations); alone, only these run",
    )
    p.add_argument(
        "--seeds",
        nargs="+",
        type=arg_type(int, 0, MAX_SEED),
        default=[0, 1, 2, 3, 4],
        metavar="SEED",
        help=f"the seeds, distinct integers in [0, {MAX_SEED}]: one trial per algorithm and "
        "seed (default 0 1 2 3 4)",
    )
    p.add_argument(
        "--timesteps",
        type=arg_type(int, 1, 10**12),
        default=None,
        help="override every config's env steps per run (quick checks)",
    )
    p.add_argument(
        "--eval-points",
        type=arg_type(int, 1, 10**4),
        default=None,
        help="override the learning-curve evaluations per run",
    )
    p.add_argument(
        "--env-id",
        type=env_id_arg,
        default=DEFAULT_ENV_ID,
        help=f"this package's env id (default {DEFAULT_ENV_ID})",
    )
    p.add_argument(
        "--random-episodes",
        type=arg_type(int, 1, 20),
        default=20,
        help="held-out random-load episodes of the evaluation (default 20)",
    )
    p.add_argument(
        "--backend",
        choices=("auto", "ray", "local"),
        default="auto",
        help="ray: Ray Tune trials; local: one after the other; auto (default): ray if "
        "installed and the command has several trials or an --address, else local",
    )
    p.add_argument(
        "--num-cpus",
        type=arg_type(int, 1, 1024),
        default=2,
        help="CPUs of a local Ray, or of the local backend's trial (default 2)",
    )
    p.add_argument(
        "--cpus-per-trial",
        type=arg_type(int, 1, 1024),
        default=None,
        help="CPUs of a trial whose recipe has several runs (restarts): it trains that many "
        "at once, in worker processes, to the same result in less time (default: "
        "--num-cpus, so such trials run one after another; with --address 1)",
    )
    p.add_argument("--address", default=None, help="Ray cluster address (default: local)")
    p.add_argument(
        "--out", default=None, help="output directory (default: runs/<env id>/benchmark)"
    )
    p.add_argument(
        "--quiet",
        action="store_true",
        help="no line per evaluation (thresholds and retries are still said)",
    )
    p.add_argument(
        "--no-bound",
        action="store_true",
        help="skip the clairvoyant bound's reference (about 30 s)",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="reuse trials already in OUT/trials with the same config and env id (a damaged "
        "record, or one whose agent no longer loads, is trained again, said in one line; a "
        "damaged references file is computed again)",
    )
    p.add_argument(
        "--no-train",
        action="store_true",
        help="with --resume: train nothing, report the reused trials only and "
        "name the missing ones",
    )
    return p


def trial_workers(cpus_per_trial: int | None, num_cpus: int, address: str | None) -> int:
    """The CPUs of a trial whose recipe has several runs (``--cpus-per-trial``): by default
    every one of ``--num-cpus`` (1 on a cluster, ``address``), so that such trials run one
    at a time and each seed's wall time is bounded by its own runs, whatever else the
    command trains (a trial with one run takes one CPU, :func:`train.core.trials.run_trials`).

    Until acld-gym 0.14.0 the CPUs were shared among the command's trials: ``--algos ppo
    sac --seeds N`` gave each trial one, and a SAC seed that needs all four runs took about
    20 min, over 15 min a seed."""
    if cpus_per_trial is not None:
        return cpus_per_trial
    return 1 if address else num_cpus


def auto_backend(n_trials: int, address: str | None, installed: bool) -> str:
    """``--backend auto``: ``"ray"`` where Ray Tune is ``installed`` and it has something to
    spread (more than one of the command's ``n_trials``, or a cluster's ``address``), else
    ``"local"``. One trial gains nothing from Ray and would pay for its start (a few
    seconds, its log lines, its files under ``~/.ray``)."""
    return "ray" if installed and (n_trials > 1 or address is not None) else "local"


def check_outputs(out: Path, trials: list[dict], backend: str, env_id: str) -> None:
    """``ValueError`` naming ``--out`` unless every file the command writes there can be
    written (the tables, the figure, the references, each trial's record and agent folder,
    Ray's storage): called before anything is computed."""
    check_directory(out, "--out")
    held = [n for n in ("policy.npz", "metadata.json") if (out / n).exists()]
    if held:  # an agent's folder (acld-gym train's --out, or a shipped agent)
        raise ValueError(
            f"--out: {str(out)!r} holds an agent ({', '.join(held)}), the --out of acld-gym "
            "train or a shipped one; a benchmark writes its tables and agents/ into a folder "
            "of its own: choose another"
        )
    names = ["results.md", "results.json", "learning_curves.png", f"references-{env_id}.json"]
    for t in trials:
        names.append(str(trial_path(Path(), t["name"], t["seed"])))
        check_directory(agent_dir(out, t["name"], t["seed"]).parent, "--out")
        try:  # each agent folder is replaced whole: it may hold no one else's files
            check_replaceable(agent_dir(out, t["name"], t["seed"]))
        except ValueError as exc:
            raise ValueError(f"--out: {exc}") from None
    if backend == "ray":
        check_directory(out / "ray", "--out")
    for name in dict.fromkeys(names):
        check_writable(out / name, "--out")


def reusable(path: Path, trial: dict, out: Path) -> dict | None:
    """The record at ``path`` of ``trial`` (same name, seed, config, env id and evaluation)
    if ``--resume`` may reuse it, else None. A damaged record (:func:`train.core.records.
    check_trial`) or one whose agent folder no longer loads (:meth:`train.agent.
    TrainedAgent.load`) is said in one line and trained again."""
    if not path.is_file():
        return None
    what = f"{trial['name']} seed {trial['seed']}"
    try:
        rec = check_trial(read_json(path), path)
    except (OSError, DataFileError) as exc:
        print(f"  {exc}: training {what} again", flush=True)
        return None
    same = {k: rec.get(k) for k in ("name", "seed", "env_id", "random_episodes")}
    if same != {k: trial[k] for k in same} or rec["config"] != json.loads(
        json.dumps(trial["config"])
    ):
        return None  # another run's record (another config or env): trained again, as asked
    from .agent import TrainedAgent

    folder = agent_dir(out, trial["name"], trial["seed"])
    try:
        TrainedAgent.load(folder)
    except (OSError, ValueError) as exc:
        print(f"  {folder}: the agent does not load ({exc}): training {what} again", flush=True)
        return None
    return rec


def resumed_references(env_id: str, out: Path, random_episodes: int, bound: bool) -> dict:
    """The references of :func:`train.core.evaluate.references`, cached in ``out``; a
    damaged cache (:func:`train.core.records.check_references`) is said in one line and
    computed again (and replaced)."""
    from .core.evaluate import references

    path = out / f"references-{env_id}.json"
    if path.is_file():
        try:
            check_references(read_json(path), path, bound)
        except (OSError, DataFileError) as exc:
            print(f"  {exc}: computing the references again", flush=True)
            refs = references(env_id, None, random_episodes, bound=bound)
            write_text(path, json.dumps(refs, indent=2) + "\n")
            return refs
    return references(env_id, path, random_episodes, bound=bound)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if len(set(args.seeds)) != len(args.seeds):
        parser.error(f"--seeds must be distinct, got {args.seeds}")
    if args.no_train and not args.resume:
        parser.error("--no-train needs --resume")
    backend = args.backend
    installed = backend != "local" and ray_available()
    if backend == "ray" and not installed:
        parser.error('Ray Tune is not installed: pip install -e ".[sweep]" (or --backend local)')
    if args.address is not None and not installed:  # a cluster is reached through Ray only
        parser.error(
            "--address needs Ray Tune: --backend ray or auto, with Ray installed "
            '(pip install -e ".[sweep]")'
        )
    specs = list(args.algos or ([] if args.config else DEFAULT_ALGOS)) + list(args.config)
    try:
        configs = [(config_path(s), *read_config(s)) for s in specs]
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    names = [name for _, name, _ in configs]
    if len(set(names)) != len(names):
        parser.error(f"two configs of one name would share their trials: {names}")
    out = Path(args.out) if args.out else Path("runs") / args.env_id / "benchmark"
    planned = []
    for path, name, data in configs:
        data = dict(data)
        if args.timesteps is not None:
            data["timesteps"] = args.timesteps
        if args.eval_points is not None:
            data["eval_points"] = args.eval_points
        try:  # with the command line's overrides, every section, before any computing
            check_buildable(TrainConfig.from_dict(data), args.env_id)
        except (TypeError, ValueError) as exc:
            parser.error(f"{path} (with the command line's overrides): {exc}")
        for seed in args.seeds:
            planned.append(
                {
                    "name": name,
                    "config": data,
                    "seed": seed,
                    "env_id": args.env_id,
                    "random_episodes": args.random_episodes,
                    "quiet": args.quiet,
                }
            )
    may_use = backend if backend != "auto" else auto_backend(len(planned), args.address, installed)
    try:  # Ray's storage checked wherever Ray may run (auto decides on the trials left, below)
        check_outputs(out, planned, may_use, args.env_id)
    except ValueError as exc:
        parser.error(str(exc))
    trials, records = [], []
    for t in planned:
        rec = reusable(trial_path(out, t["name"], t["seed"]), t, out) if args.resume else None
        if rec is not None:
            records.append(rec)
        else:
            trials.append(t)
    if backend == "auto":  # on the trials left to train: the reused ones need no Ray
        backend = auto_backend(len(trials), args.address, installed)
    if args.no_train:
        for t in trials:
            print(f"  missing: {t['name']} seed {t['seed']} (not trained: --no-train)")
        trials = []
        if not records:
            parser.error(f"--no-train: no trials to report in {out / 'trials'}")
    t0 = time.perf_counter()
    print(
        f"benchmark on {args.env_id}: {', '.join(names)} x seeds "
        f"{' '.join(map(str, args.seeds))}: {len(trials)} runs to train ({len(records)} "
        f"reused), backend {backend} -> {out}/",
        flush=True,
    )
    refs = resumed_references(args.env_id, out, args.random_episodes, not args.no_bound)
    workers = trial_workers(args.cpus_per_trial, args.num_cpus, args.address)
    records += run_trials(trials, out, backend, args.num_cpus, args.address, workers)
    wall = time.perf_counter() - t0
    summary = summarize(records, refs)
    summary["wall_seconds"] = wall
    summary["backend"] = backend
    summary["command"] = "python -m train.benchmark " + " ".join(
        sys.argv[1:] if argv is None else argv
    )
    runs_wall = sum(r["wall_seconds"] for r in records)
    text = markdown(summary) + (
        f"\nWall time of this command: {wall:.0f} s ({backend}, "
        f"{len(trials)} runs trained, {len(records) - len(trials)} "
        f"reused); the runs' own wall times (training and "
        f"evaluation) add up to {runs_wall:.0f} s.\n"
    )
    # the tables both or neither (a full disk: the previous pair stays), then the figure
    write_texts(
        {out / "results.md": text, out / "results.json": json.dumps(summary, indent=1) + "\n"}
    )
    plot_curves(summary, out / "learning_curves.png")
    print(text)
    print(f"wrote {out}/results.md, results.json, learning_curves.png, trials/")
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
