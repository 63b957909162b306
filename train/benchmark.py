"""``python -m train.benchmark``: reinforcement learning from scratch on ACLDBeam, no teacher.

Trains every algorithm (one YAML file each under ``train/benchmark/``: hyperparameters
and a fixed env-step budget, the same for every seed) with every seed, from random
initialisation, on the env's observation and reward only. Then evaluates each final
policy deterministically through the env (+/-120 V, 1 ms, default Kalman observer):
ISE / ISE_LQR on thesis cases 1, 2, 3 (seed 0) and on the held-out random set
(``train.compare.HELDOUT_SEEDS``). LQR, SMC, MPC and the clairvoyant bound are used
only to normalise and report these numbers.

Writes to ``--out`` (default ``runs/benchmark``), atomically:

* ``results.md`` / ``results.json``: per algorithm the interquartile mean (IQM) over
  seeds with 95 % stratified-bootstrap intervals, the training wall time, the
  issue's goals, and every seed's numbers;
* ``learning_curves.png``: IQM ISE / LQR vs env steps with 95 % bands, and the LQR,
  SMC, MPC and bound levels;
* ``trials/<name>-s<seed>.json`` (one per run) and ``references-<env id>.json``.

Runs go through Ray Tune when it is installed (``--backend ray``: one trial per CPU,
local with ``--num-cpus`` or on a cluster with ``--address``), else one after the
other (``--backend local``).

Examples::

    python -m train.benchmark                                  # 5 algorithms x 5 seeds
    python -m train.benchmark --algos vrs --seeds 0 1 2 3 4 --out runs/benchmark/vrs
    python -m train.benchmark --config train/benchmark/ablation_vrs_return.yaml \\
        --seeds 0 1 2 --out runs/benchmark/ablation_vrs_return
    python -m train.benchmark --env-id ACLDBeam-v1 --backend ray --num-cpus 2
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import yaml

from acld_gym.util.atomic import save_figure, write_text

from .bench.evaluate import CASES, DEFAULT_ENV_ID

__all__ = ["CONFIG_DIR", "DEFAULT_ALGOS", "load_algo_config", "run_trial", "run_trials",
           "summarize", "markdown", "plot_curves", "main"]

CONFIG_DIR = Path(__file__).resolve().parent / "benchmark"
#: The benchmark's algorithms (``train/benchmark/<name>.yaml``).
DEFAULT_ALGOS = ("vrs", "ars", "ppo", "sac", "tqc")
REFERENCES = ("lqr", "smc", "mpc", "bound")


def load_algo_config(spec: str | Path) -> tuple[str, dict]:
    """``(name, mapping)`` of a config: a name under ``train/benchmark/`` or a YAML path."""
    path = Path(spec)
    if not path.suffix:
        path = CONFIG_DIR / f"{spec}.yaml"
    if not path.is_file():
        raise FileNotFoundError(f"config {str(spec)!r}: no file {str(path)!r}")
    data = yaml.safe_load(path.read_text()) or {}
    from .bench.config import AlgoConfig

    AlgoConfig.from_dict(data)  # validate early
    return path.stem, data


def run_trial(name: str, config: dict, seed: int, env_id: str = DEFAULT_ENV_ID,
              random_episodes: int = 20, out: str | Path | None = None) -> dict:
    """Train one (config, seed) and evaluate it; returns the trial's record (JSON-able):
    the learning curve (mean ISE per case at each evaluation, batched), the final ISE
    per case (single-env rollouts) and the training wall time (evaluations excluded).
    With ``out``, the final policy is saved as an agent in :func:`agent_dir`."""
    import torch

    from .bench.algos import train_algo
    from .bench.config import AlgoConfig
    from .bench.evaluate import batched_ise, eval_episodes, rollout_ise

    torch.set_num_threads(1)
    cfg = AlgoConfig.from_dict(config)
    episodes = eval_episodes(random_episodes)
    curve = []

    def on_eval(steps: int, policy) -> None:
        ise = batched_ise(policy, env_id, episodes)
        curve.append({"steps": int(steps), "ise": {str(c): v for c, v in ise.items()}})

    t0 = time.perf_counter()
    policy, record = train_algo(cfg, seed, env_id, on_eval)
    wall = time.perf_counter() - t0
    final = rollout_ise(policy, env_id, episodes)
    rec = {"name": name, "algo": cfg.algo, "seed": int(seed), "env_id": env_id,
            "config": config, "random_episodes": int(random_episodes),
            "budget": cfg.timesteps, "steps": int(record.get("steps", 0)),
            "train_seconds": float(record["train_seconds"]),
            "train_cpu_seconds": float(record.get("train_cpu_seconds", np.nan)),
            "wall_seconds": wall,
            "final_ise": {str(c): v for c, v in final.items()}, "curve": curve,
            "record": {k: v for k, v in record.items()
                       if k not in ("train_seconds", "train_cpu_seconds")}}
    if out is not None:
        save_agent(policy, rec, Path(out))
    return rec


def _trial_path(out: Path, name: str, seed: int) -> Path:
    return out / "trials" / f"{name}-s{seed}.json"


def agent_dir(out: Path, name: str, seed: int) -> Path:
    """Where a trial's final policy is saved as an agent (:class:`train.agent.TrainedAgent`)."""
    return Path(out) / "agents" / f"{name}-s{seed}"


def policy_program(policy):
    """A trained benchmark policy as a :class:`train.agent.ActorProgram` (numpy arrays and
    a JSON list of operations: loading it never runs code)."""
    from .agent import ActorProgram, export_sb3, linear_program
    from .bench.sb3_policies import SB3Policy
    from .bench.search import LinearDirectionActor

    if isinstance(policy, LinearDirectionActor):
        return linear_program(policy.theta, policy.transform, policy.features)
    if isinstance(policy, SB3Policy):  # direction features (an env wrapper), then VecNormalize
        prog = export_sb3(policy.model, policy.obs_norm)
        if policy.features == "direction":
            prog = ActorProgram([{"op": "direction"}, *prog.ops], prog.arrays)
        return prog
    raise TypeError(f"cannot export a {type(policy).__name__}")


def save_agent(policy, rec: dict, out: Path) -> Path:
    """Save a trial's final policy as an agent directory (``policy.npz``,
    ``metadata.json`` with ``training: "from scratch"``, no teacher, the command, config,
    budget, times and the observation fingerprint of the env it was trained on)."""
    import gymnasium as gym

    from acld_gym.envs.fingerprint import observation_fingerprint

    from .agent import TrainedAgent
    from .callbacks import CURVE_FILE
    from .cli import versions

    probe = gym.make(rec["env_id"])
    meta = {"algo": rec["algo"], "seed": rec["seed"], "benchmark": rec["name"],
            "command": f"python -m train.benchmark --config {rec['name']} "
                       f"--seeds {rec['seed']} --env-id {rec['env_id']}",
            "config": rec["config"], "training": "from scratch", "teacher": None,
            "residual": None, "timesteps": rec["steps"], "budget": rec["budget"],
            "train_seconds": round(rec["train_seconds"], 1),
            "train_cpu_seconds": round(rec["train_cpu_seconds"], 1),
            "final_ise": rec["final_ise"], "versions": versions(),
            "env": {"id": rec["env_id"], "kwargs": {}},
            "observation": observation_fingerprint(probe)}
    probe.close()
    d = TrainedAgent(policy_program(policy), meta, rec["algo"]).save(
        agent_dir(out, rec["name"], rec["seed"]))
    # its learning curve on the thesis cases and the random set, batched evaluations
    lines = ["timesteps,case,ise"] + [f"{p['steps']},{c},{ise!r}" for p in rec["curve"]
                                      for c, ise in p["ise"].items()]
    write_text(d / CURVE_FILE, "\n".join(lines) + "\n")
    return d


def _tune_trainable(config: dict) -> None:  # pragma: no cover - runs inside Ray workers
    from ray import tune

    kwargs = json.loads(config["trial"])
    out = Path(kwargs["out"])
    rec = run_trial(**kwargs)
    # written here too, so that --resume finds the finished runs after an interruption (on a
    # cluster the driver writes them again from the reported results)
    write_text(_trial_path(out, rec["name"], rec["seed"]), json.dumps(rec) + "\n")
    tune.report({"train_seconds": rec["train_seconds"], "record": json.dumps(rec)})


def run_trials(trials: list[dict], out: Path, backend: str = "local", num_cpus: int = 2,
               address: str | None = None) -> list[dict]:
    """Run ``trials`` (keyword arguments of :func:`run_trial`) and write each record to
    ``out/trials/``; ``backend="ray"`` runs them as Ray Tune trials (one CPU each)."""
    records = []
    if backend == "local":
        for t in trials:
            rec = run_trial(**t, out=out)
            write_text(_trial_path(out, rec["name"], rec["seed"]), json.dumps(rec) + "\n")
            print(f"  {rec['name']} seed {rec['seed']}: trained in {rec['train_seconds']:.0f} s",
                  flush=True)
            records.append(rec)
        return records
    import ray
    from ray import tune

    if not ray.is_initialized():
        ray.init(address=address) if address else ray.init(num_cpus=num_cpus)
    # one grid point per run: run_trial's arguments as JSON text (Tune's loggers sort config
    # keys, and the load weights mix int and str keys)
    tuner = tune.Tuner(
        tune.with_resources(_tune_trainable, {"cpu": 1}),
        param_space={"trial": tune.grid_search(
            [json.dumps({**t, "out": str(out.resolve())}) for t in trials])},
        tune_config=tune.TuneConfig(trial_dirname_creator=lambda t: f"trial_{t.trial_id}"),
        run_config=tune.RunConfig(storage_path=str((out / "ray").resolve()), name="benchmark",
                                  verbose=0))
    results = tuner.fit()
    for res in results:
        if res.error is not None:
            raise RuntimeError(f"a Ray trial failed: {res.error}")
        rec = json.loads(res.metrics["record"])
        write_text(_trial_path(out, rec["name"], rec["seed"]), json.dumps(rec) + "\n")
        records.append(rec)
    return records


def summarize(records: list[dict], refs: dict) -> dict:
    """Per config: IQM and 95 % stratified-bootstrap CI of ISE / LQR per case over the
    seeds, the per-seed values, wall time, and the goals of issue 10."""
    from .bench.stats import iqm, iqm_with_ci

    lqr = refs["lqr"]
    out: dict = {"env_id": refs["env_id"], "episodes": refs["episodes"], "algorithms": {},
                 "references": {k: {c: refs[k][c] / lqr[c] for c in lqr}
                                for k in ("passive", *REFERENCES) if k in refs}}
    for name in dict.fromkeys(r["name"] for r in records):
        runs = sorted((r for r in records if r["name"] == name), key=lambda r: r["seed"])
        rel = np.array([[r["final_ise"][str(c)] / lqr[str(c)] for c in CASES] for r in runs])
        stats = {str(c): iqm_with_ci(rel[:, j]) for j, c in enumerate(CASES)}
        smc = out["references"].get("smc", {})
        bound = out["references"].get("bound")
        goals = {
            "beats_lqr_and_smc_iqm": all(stats[c]["iqm"] < min(1.0, smc.get(c, np.inf))
                                         for c in ("1", "2", "random")),
            "every_seed_beats_lqr": bool((rel[:, [0, 1, 3]] < 1.0).all()),
            "case3_within_2pct_of_lqr": stats["3"]["iqm"] <= 1.02,
            "train_wall_within_15_min": max(r["train_seconds"] for r in runs) <= 900.0,
            "train_cpu_within_15_min": max(r.get("train_cpu_seconds", np.inf)
                                           for r in runs) <= 900.0,
        }
        if bound is not None:
            goals["stretch_within_1.25x_bound"] = all(
                stats[c]["iqm"] <= 1.25 * bound[c] for c in ("1", "2"))
        curve_steps = [p["steps"] for p in runs[0]["curve"]]
        n_pts = min(len(r["curve"]) for r in runs)
        curve = []
        for k in range(n_pts):
            pt = {"steps": curve_steps[k]}
            for c in CASES:
                vals = np.array([r["curve"][k]["ise"][str(c)] / lqr[str(c)] for r in runs])
                pt[str(c)] = iqm_with_ci(vals, reps=500)
            curve.append(pt)
        out["algorithms"][name] = {
            "algo": runs[0]["algo"], "budget": runs[0]["budget"],
            "seeds": [r["seed"] for r in runs],
            "ise_rel_lqr": stats, "goals": goals,
            "train_seconds": {"iqm": iqm([r["train_seconds"] for r in runs]),
                              "max": max(r["train_seconds"] for r in runs)},
            "train_cpu_seconds": {"iqm": iqm([r.get("train_cpu_seconds", np.nan)
                                              for r in runs]),
                                  "max": max(r.get("train_cpu_seconds", np.nan) for r in runs)},
            "per_seed": [{"seed": r["seed"], "train_seconds": r["train_seconds"],
                          "train_cpu_seconds": r.get("train_cpu_seconds", np.nan),
                          **{str(c): float(rel[i, j]) for j, c in enumerate(CASES)}}
                         for i, r in enumerate(runs)],
            "curve": curve}
    return out


def markdown(summary: dict) -> str:
    """The summary as markdown: the IQM table, the goals and the per-seed table."""
    def cell(s):
        return f"{s['iqm']:.3f} [{s['ci_low']:.3f}, {s['ci_high']:.3f}]"

    n_rand = len(summary["episodes"]["random"])
    lines = [f"ISE / ISE_LQR on `{summary['env_id']}` (+/-120 V, 1 ms, Kalman observer, "
             f"deterministic policy): IQM over seeds [95 % stratified-bootstrap CI]; thesis "
             f"cases seed 0, `random` = mean ISE over {n_rand} held-out episodes / LQR's.",
             "", "| algorithm | budget [env steps] | seeds | case 1 | case 2 | case 3 | random "
             "| train wall / CPU time per seed [s] (IQM; max) |",
             "|---|---|---|---|---|---|---|---|"]
    for name, a in summary["algorithms"].items():
        t, cpu = a["train_seconds"], a["train_cpu_seconds"]
        lines.append(f"| {name} ({a['algo']}) | {a['budget']:,} | {len(a['seeds'])} | "
                     + " | ".join(cell(a["ise_rel_lqr"][str(c)]) for c in CASES)
                     + f" | {t['iqm']:.0f} / {cpu['iqm']:.0f}; {t['max']:.0f} / {cpu['max']:.0f} |")
    for ref, vals in summary["references"].items():
        lines.append(f"| {ref} (reference) | - | - | "
                     + " | ".join(f"{vals[str(c)]:.3f}" for c in CASES) + " | - |")
    lines += ["", "Goals of issue 10 (IQM over seeds; every seed on cases 1, 2, random):", "",
              "| algorithm | " + " | ".join(next(iter(summary["algorithms"].values()))["goals"])
              + " |", "|---" * (1 + len(next(iter(summary["algorithms"].values()))["goals"]))
              + "|"]
    for name, a in summary["algorithms"].items():
        lines.append(f"| {name} | " + " | ".join("yes" if v else "no" for v in a["goals"].values())
                     + " |")
    lines += ["", "Per seed (ISE / LQR):", "",
              "| algorithm | seed | case 1 | case 2 | case 3 | random | train wall / CPU [s] |",
              "|---|---|---|---|---|---|---|"]
    for name, a in summary["algorithms"].items():
        for s in a["per_seed"]:
            vals = " | ".join(f"{s[str(c)]:.3f}" for c in CASES)
            lines.append(f"| {name} | {s['seed']} | {vals} | {s['train_seconds']:.0f} / "
                         f"{s['train_cpu_seconds']:.0f} |")
    return "\n".join(lines) + "\n"


def plot_curves(summary: dict, path: Path) -> Path:
    """IQM ISE / LQR vs env steps per case with 95 % bands and the reference levels."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(17, 4.2), sharex=False)
    styles = {"lqr": ("k", "--"), "smc": ("tab:gray", ":"), "mpc": ("tab:purple", "-."),
              "bound": ("tab:green", "--")}
    for ax, case in zip(axes, CASES, strict=True):
        for name, a in summary["algorithms"].items():
            steps = np.array([p["steps"] for p in a["curve"]], dtype=float)
            mid = np.array([p[str(case)]["iqm"] for p in a["curve"]])
            lo = np.array([p[str(case)]["ci_low"] for p in a["curve"]])
            hi = np.array([p[str(case)]["ci_high"] for p in a["curve"]])
            (line,) = ax.plot(steps, mid, marker=".", lw=1.2, label=name)
            ax.fill_between(steps, lo, hi, color=line.get_color(), alpha=0.2, lw=0)
        for ref, (color, ls) in styles.items():
            if ref in summary["references"]:
                ax.axhline(summary["references"][ref][str(case)], color=color, ls=ls, lw=1,
                           label=ref.upper() if ref != "bound" else "bound")
        ax.set_xscale("symlog", linthresh=1e4)  # step 0 (the initial actor) included
        ax.set_xlim(left=0)
        ax.set_title(f"load case {case}" if case != "random" else "held-out random loads")
        ax.set_xlabel("env steps")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("ISE / ISE$_{LQR}$ (IQM over seeds, 95 % CI)")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Teacher-free RL on {summary['env_id']}", fontsize=10)
    fig.tight_layout()
    try:
        return save_figure(fig, path, dpi=110)
    finally:
        plt.close(fig)


def _ray_available() -> bool:
    try:
        import ray  # noqa: F401
        from ray import tune  # noqa: F401
    except ImportError:
        return False
    return True


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m train.benchmark", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--algos", nargs="+", default=None, metavar="NAME",
                   help=f"configs under train/benchmark/ (default: {' '.join(DEFAULT_ALGOS)})")
    p.add_argument("--config", nargs="+", default=(), metavar="YAML",
                   help="further config files (e.g. the ablations); alone, only these run")
    p.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2, 3, 4])
    p.add_argument("--timesteps", type=int, default=None,
                   help="override every config's env-step budget (quick checks)")
    p.add_argument("--eval-points", type=int, default=None,
                   help="override the learning-curve evaluations per run")
    p.add_argument("--env-id", default=DEFAULT_ENV_ID, help=f"(default {DEFAULT_ENV_ID})")
    p.add_argument("--random-episodes", type=int, default=20,
                   help="held-out random-load episodes of the evaluation (default 20)")
    p.add_argument("--backend", choices=("auto", "ray", "local"), default="auto",
                   help="ray: Ray Tune trials; local: one after the other; auto: ray if "
                        "installed")
    p.add_argument("--num-cpus", type=int, default=2, help="CPUs of a local Ray (default 2)")
    p.add_argument("--address", default=None, help="Ray cluster address (default: local)")
    p.add_argument("--out", default="runs/benchmark", help="output directory")
    p.add_argument("--no-bound", action="store_true",
                   help="skip the clairvoyant bound's reference (about 30 s)")
    p.add_argument("--resume", action="store_true",
                   help="reuse trials already in OUT/trials with the same config and env id")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if any(s < 0 for s in args.seeds) or len(set(args.seeds)) != len(args.seeds):
        parser.error(f"--seeds must be distinct integers >= 0, got {args.seeds}")
    for flag in ("timesteps", "eval_points", "num_cpus"):
        value = getattr(args, flag)
        if value is not None and value < 1:
            parser.error(f"--{flag.replace('_', '-')} must be positive, got {value}")
    if not 1 <= args.random_episodes <= 20:
        parser.error(f"--random-episodes must be in 1..20, got {args.random_episodes}")
    backend = args.backend
    if backend == "auto":
        backend = "ray" if _ray_available() else "local"
    elif backend == "ray" and not _ray_available():
        parser.error('Ray Tune is not installed: pip install -e ".[sweep]" (or --backend local)')
    specs = list(args.algos or ([] if args.config else DEFAULT_ALGOS)) + list(args.config)
    try:
        configs = [load_algo_config(s) for s in specs]
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    out = Path(args.out)
    trials, records = [], []
    for name, data in configs:
        data = dict(data)
        if args.timesteps is not None:
            data["timesteps"] = args.timesteps
        if args.eval_points is not None:
            data["eval_points"] = args.eval_points
        for seed in args.seeds:
            path = _trial_path(out, name, seed)
            if args.resume and path.is_file():
                rec = json.loads(path.read_text())
                if (rec.get("config") == json.loads(json.dumps(data))
                        and rec.get("env_id") == args.env_id
                        and rec.get("random_episodes") == args.random_episodes):
                    records.append(rec)
                    continue
            trials.append({"name": name, "config": data, "seed": seed, "env_id": args.env_id,
                           "random_episodes": args.random_episodes})
    from .bench.evaluate import references

    t0 = time.perf_counter()
    refs = references(args.env_id, out / f"references-{args.env_id}.json",
                      args.random_episodes, bound=not args.no_bound)
    print(f"{len(trials)} runs ({len(records)} reused), backend {backend}, env {args.env_id}",
          flush=True)
    records += run_trials(trials, out, backend, args.num_cpus, args.address)
    wall = time.perf_counter() - t0
    summary = summarize(records, refs)
    summary["wall_seconds"] = wall
    summary["backend"] = backend
    summary["command"] = "python -m train.benchmark " + " ".join(
        sys.argv[1:] if argv is None else argv)
    runs_wall = sum(r["wall_seconds"] for r in records)
    text = markdown(summary) + (f"\nWall time of this command: {wall:.0f} s ({backend}, "
                                f"{len(trials)} runs trained, {len(records) - len(trials)} "
                                f"reused); the runs' own wall times (training and "
                                f"evaluation) add up to {runs_wall:.0f} s.\n")
    write_text(out / "results.md", text)
    write_text(out / "results.json", json.dumps(summary, indent=1) + "\n")
    plot_curves(summary, out / "learning_curves.png")
    print(text)
    print(f"wrote {out}/results.md, results.json, learning_curves.png, trials/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
