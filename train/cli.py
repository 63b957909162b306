"""``python -m train ALGO``: train one agent with the benchmark's recipe.

``ALGO`` names a recipe under ``train/recipes/`` (``ppo``, ``sac``, ``vrs``, ``ars``,
``tqc``); ``--config`` gives another file of the same schema (:class:`train.config.TrainConfig`,
e.g. an ablation or the opt-in DAgger start ``train/recipes/ppo_dagger.yaml``). The run is
exactly one trial of ``python -m train.benchmark`` (the same code builds the env, trains
and evaluates), so ``python -m train ppo --seed N`` gives the
agent that ``python -m train.benchmark --algos ppo --seeds N`` saves in
``<out>/agents/ppo-sN``, bit for bit on one machine.

Writes to ``--out`` (default ``runs/<env id>/<recipe>-s<seed>``, so runs on different
levels never overwrite one another): the agent as ``policy.npz`` +
``metadata.json`` (loads with :meth:`train.agent.TrainedAgent.load`; the metadata records
the command, seed, config, versions, how it was trained, and the observation
fingerprint), ``learning_curve.csv`` (ISE per case during training) and ``trial.json``
(the benchmark's record of the run, every retry with its reason included). Prints the env
id it trains on, a line per evaluation with the current validation score (``--quiet``:
none), the retry threshold of a recipe with several runs resolved on that level and every
retry with its reason, then ISE / LQR of the final policy on thesis cases 1, 2, 3 and the
held-out random loads.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path

from acld_gym import ENV_ID
from acld_gym.util.atomic import check_writable
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type

from .agent_files import check_replaceable
from .config import ALGOS, CONFIG_DIR, config_path, parse_load_case, read_config

__all__ = [
    "main",
    "build_parser",
    "configure",
    "default_out",
    "env_id_arg",
    "RECIPES",
    "MAX_SEED",
]

#: The recipes ``python -m train`` knows by name (a file ``train/recipes/<algo>.yaml``).
RECIPES = tuple(a for a in ALGOS if (CONFIG_DIR / f"{a}.yaml").is_file())
#: Seeds: numpy's legacy seeding (used by SB3) takes integers below 2**32.
MAX_SEED = 2**32 - 1
_positive_int = arg_type(int, 1, 10**12)
_seed = arg_type(int, 0, MAX_SEED)
_param_noise = arg_type(float, 0.0)  # its bound (per mesh) is checked by the env's config
_episodes = arg_type(int, 1, 20)
_cpus = arg_type(int, 1, 1024)


def env_id_arg(text: str) -> str:
    """``--env-id`` value: one of this package's registered ids, matched as a plain string
    (:func:`acld_gym.envs.presets.check_env_id`), before anything is computed; no other
    Gymnasium id (an env of another package cannot take the beam's options)."""
    from acld_gym.envs.presets import check_env_id

    try:
        return check_env_id(text, "expected")
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err).replace("expected must be", "expected")) from None


def default_out(env_id: str, name: str, seed: int) -> Path:
    """``--out``'s default: ``runs/<env id>/<recipe>-s<seed>`` (the env id named, so a run
    on one level never replaces another's)."""
    return Path("runs") / env_id / f"{name}-s{seed}"


def _load_case_arg(text: str):
    """``--load-case`` value: 1, 2, 3 or ``random`` (:func:`train.config.parse_load_case`)."""
    try:
        return parse_load_case(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog("python -m train"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "algo", choices=RECIPES, help="the algorithm (its recipe: train/recipes/<algo>.yaml)"
    )
    p.add_argument(
        "--config",
        metavar="YAML",
        default=None,
        help="another config file of the same algorithm (default: the recipe)",
    )
    p.add_argument("--seed", type=_seed, default=0, help=f"seed in [0, {MAX_SEED}] (default 0)")
    p.add_argument(
        "--timesteps",
        type=_positive_int,
        default=None,
        help="env steps per run, the whitening's included (ppo and sac: whiten_steps of "
        "the initial policy first; default: the config's timesteps)",
    )
    p.add_argument(
        "--n-envs",
        type=arg_type(int, 1, 2**16),
        default=None,
        help="sub-envs of the batched env (default: the config's)",
    )
    p.add_argument(
        "--load-case",
        type=_load_case_arg,
        default=None,
        help="train on one load case: 1, 2, 3 or random (default: the config's loads)",
    )
    p.add_argument(
        "--param-noise",
        type=_param_noise,
        default=None,
        help="per-episode parameter randomization of the training env (an env "
        "option; default: the config's, else none)",
    )
    p.add_argument(
        "--env-id",
        type=env_id_arg,
        default=ENV_ID,
        help=f"this package's env id (default {ENV_ID})",
    )
    p.add_argument(
        "--random-episodes",
        type=_episodes,
        default=20,
        help="held-out random-load episodes of the evaluation, 1..20 (default 20)",
    )
    p.add_argument(
        "--cpus",
        type=_cpus,
        default=1,
        help="runs of a recipe with several (restarts: ppo, sac) trained at once, in worker "
        "processes: the same agent in less wall time (default 1)",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        default=None,
        help="output directory (default: runs/<env id>/<recipe>-s<seed>)",
    )
    p.add_argument(
        "--quiet",
        action="store_true",
        help="no line per evaluation (the retry threshold and any retry are still said)",
    )
    return p


def configure(args: argparse.Namespace) -> tuple[str, dict]:
    """``(recipe name, config mapping)`` of the parsed arguments: the recipe (or
    ``--config``) with the command line's overrides, validated; ``ValueError`` naming the
    flag or the key."""
    name, data = read_config(args.config or args.algo)
    if data["algo"] != args.algo:
        raise ValueError(f"--config: {args.config} is a {data['algo']!r} config, not {args.algo!r}")
    data = dict(data)
    if args.timesteps is not None:
        data["timesteps"] = args.timesteps
    if args.n_envs is not None:
        data["n_envs"] = args.n_envs
    if args.load_case is not None:
        data["loads"] = {args.load_case: 1}
    if args.param_noise is not None:
        data["env_kwargs"] = {**data.get("env_kwargs", {}), "param_noise": args.param_noise}
    from .config import TrainConfig
    from .config_checks import check_buildable

    try:
        cfg = TrainConfig.from_dict(data)
    except ValueError as exc:
        raise ValueError(f"the command line's overrides: {exc}") from None
    try:  # every setting the algorithm reads, before training
        check_buildable(cfg, args.env_id)
    except ValueError as exc:
        raise ValueError(f"{config_path(args.config or args.algo)}: {exc}") from None
    return name, data


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        name, data = configure(args)
    except (OSError, ValueError) as exc:
        parser.error(str(exc))  # exit status 2, no traceback
    out = Path(args.out or default_out(args.env_id, name, args.seed))
    if out.exists() and not out.is_dir():
        parser.error(f"--out: {str(out)!r} exists and is not a directory")
    try:  # before any training: an unusable --out fails now, not after the run
        check_writable(out / "metadata.json", "--out")
    except ValueError as exc:
        parser.error(str(exc))
    try:  # the agent replaces the folder whole: it may hold none of the user's files
        check_replaceable(out)
    except ValueError as exc:
        parser.error(f"--out: {exc}")
    from .config import TrainConfig
    from .core.evaluate import eval_episodes, lqr_ise
    from .core.trials import run_trial, save_agent, trained_line

    cfg = TrainConfig.from_dict(data)
    command = "python -m train " + " ".join(
        shlex.quote(a) for a in (sys.argv[1:] if argv is None else argv)
    )
    # several runs: all of them (restarts), or the next only while a run fails (restart_above)
    upto = "up to " if cfg.restart_above is not None else ""
    runs = f" ({upto}{cfg.restarts} runs of {cfg.timesteps})" if cfg.restarts > 1 else ""
    if runs and args.cpus > 1:
        runs = runs[:-1] + f", {min(args.cpus, cfg.restarts)} at once)"
    rule = f"; a run retried while its validation cost is above {cfg.restart_above}" if upto else ""
    print(
        f"training {cfg.algo.upper()} ({name}, {cfg.training}) on {args.env_id} for {upto}"
        f"{cfg.budget} env steps{runs}, seed {args.seed}{rule} -> {out}/",
        flush=True,
    )
    rec, policy = run_trial(
        name,
        data,
        args.seed,
        args.env_id,
        args.random_episodes,
        command=command,
        workers=args.cpus,  # train_algo takes at most one per run
        quiet=args.quiet,
    )
    save_agent(policy, rec, out, {"trial.json": json.dumps(rec) + "\n"})  # all or none
    episodes = eval_episodes(args.random_episodes)
    lqr = lqr_ise(args.env_id, episodes)
    rel = "  ".join(f"case {c}: {rec['final_ise'][str(c)] / lqr[c]:.3f}" for c in episodes)
    print(f"{trained_line(rec)}; validation cost {rec['validation_cost']:.4f}")
    print(f"ISE / LQR on {args.env_id}  {rel}")
    print(f"wrote {out}/: policy.npz + metadata.json (the agent), learning_curve.csv, trial.json")
    return 0
