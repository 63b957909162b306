"""``python -m train.sweep``: seeds x learning rates with Ray Tune.

Each trial is one ``python -m train`` run of the recipe (:func:`trial`: one benchmark trial)
scored by the mean over the thesis cases of the final policy's ISE relative to LQR (lower
is better).
Locally Ray starts with ``--num-cpus`` workers (one trial per CPU); with
``--address`` (or ``RAY_ADDRESS``) the same command runs on a Ray cluster.
Ray is the optional extra ``pip install -e ".[sweep]"`` (Tune only; RLlib
cannot share an environment with gymnasium 1.4).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from acld_gym.util.atomic import check_directory
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type, run_main

from .cli import MAX_SEED, RECIPES

__all__ = ["trial", "score", "main"]

#: The cases a sweep's trials are scored on.
THESIS = ("1", "2", "3")


def score(rec: dict, lqr: dict) -> float:
    """Mean over the thesis cases of the final ISE / ISE_LQR of a trial record
    (:func:`train.core.trials.run_trial`); ``lqr``: ``{case: ise}``, keys as strings."""
    missing = [c for c in THESIS if c not in rec.get("final_ise", {})]
    if missing:
        raise ValueError(f"the trial record has no final ISE on case(s) {missing}")
    return sum(rec["final_ise"][c] / lqr[c] for c in THESIS) / len(THESIS)


def trial_data(config: dict) -> tuple[str, dict]:
    """The recipe ``config["algo"]``'s name and data with a trial's overrides: timesteps,
    learning_rate, n_envs where given (not None), else the recipe's. The one place they
    are applied, for the trials and for the checks before any (:func:`check_args`)."""
    from .config import read_config

    name, data = read_config(config["algo"])
    if config.get("timesteps") is not None:
        data = dict(data, timesteps=int(config["timesteps"]))
    if config.get("learning_rate") is not None:
        data["model"] = {**data["model"], "learning_rate": float(config["learning_rate"])}
    if config.get("n_envs") is not None:
        data["n_envs"] = int(config["n_envs"])
    return name, data


def trial(config: dict, out: str | Path) -> dict:
    """Train the recipe ``config["algo"]`` (overridden: seed; optional timesteps,
    learning_rate / n_envs) as one benchmark trial, save the agent in ``out``; returns
    ``{"ise_rel_lqr": score}`` (:func:`score`)."""
    from .core.evaluate import lqr_ise
    from .core.trials import run_trial, save_agent

    name, data = trial_data(config)
    rec, policy = run_trial(
        name,
        data,
        int(config["seed"]),
        random_episodes=1,
        command=f"python -m train.sweep (trial {config})",
    )
    save_agent(policy, rec, Path(out))
    episodes = {int(c): (0,) for c in THESIS}
    lqr = lqr_ise(episodes=episodes)
    return {"ise_rel_lqr": score(rec, {str(c): v for c, v in lqr.items()})}


def _tune_trainable(config: dict) -> None:
    from ray import tune

    out = Path(tune.get_context().get_trial_dir()) / "run"
    tune.report(trial(config, out))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog("python -m train.sweep"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("algo", choices=RECIPES)
    p.add_argument("--seeds", type=arg_type(int, 0, MAX_SEED), nargs="+", default=[0, 1, 2])
    p.add_argument(
        "--learning-rates",
        type=arg_type(float, 0.0, 1.0, low_open=True),
        nargs="+",
        default=None,
        help="grid of learning rates in (0, 1] (default: the config's)",
    )
    p.add_argument(
        "--timesteps",
        type=arg_type(int, 1, 10**12),
        default=None,
        help="env steps per trial (default: the recipe's timesteps)",
    )
    p.add_argument(
        "--num-cpus",
        type=arg_type(int, 1, 1024),
        default=2,
        help="CPUs for a local Ray (default 2)",
    )
    p.add_argument("--address", default=None, help="Ray cluster address (default: local)")
    p.add_argument("--out", default="runs/sweep", help="Tune's storage directory")
    return p


def check_args(args: argparse.Namespace) -> None:
    """``ValueError`` naming the argument unless the sweep can run: distinct seeds and
    learning rates, the recipe with every override of the grid valid and buildable
    (:func:`train.config_checks.check_buildable`), ``--out`` not a file (its directory is
    checked, and made, once Ray is there). Nothing is computed, Ray not started."""
    from .config import TrainConfig
    from .config_checks import check_buildable

    for flag, values in (("--seeds", args.seeds), ("--learning-rates", args.learning_rates)):
        if values and len(set(values)) != len(values):
            raise ValueError(f"{flag} must be distinct, got {values}")
    for lr in args.learning_rates or [None]:
        config = {"algo": args.algo, "timesteps": args.timesteps, "learning_rate": lr}
        try:
            cfg = TrainConfig.from_dict(trial_data(config)[1])
        except ValueError as exc:
            raise ValueError(f"--timesteps / --learning-rates: {exc}") from None
    check_buildable(cfg)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out: {str(out)!r} exists and is not a directory")


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        check_args(args)
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    try:
        from ray import tune

        from train.core.trials import init_ray
    except ImportError:
        parser.error('Ray Tune is not installed: pip install -e ".[sweep]"')
    try:
        check_directory(args.out, "--out")
    except ValueError as exc:
        parser.error(str(exc))
    init_ray(args.address, args.num_cpus)
    space = {
        "algo": args.algo,
        "timesteps": args.timesteps,
        "seed": tune.grid_search(args.seeds),
        "learning_rate": (tune.grid_search(args.learning_rates) if args.learning_rates else None),
    }
    tuner = tune.Tuner(
        tune.with_resources(_tune_trainable, {"cpu": 1}),
        param_space=space,
        tune_config=tune.TuneConfig(metric="ise_rel_lqr", mode="min"),
        run_config=tune.RunConfig(storage_path=str(Path(args.out).resolve()), name=args.algo),
    )
    results = tuner.fit()
    df = results.get_dataframe()
    cols = [c for c in ("config/seed", "config/learning_rate", "ise_rel_lqr") if c in df]
    print(df[cols].sort_values("ise_rel_lqr").to_string(index=False))
    best = results.get_best_result()
    print(f"best: {best.config} -> ISE/LQR {best.metrics['ise_rel_lqr']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
