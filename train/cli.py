"""``python -m train ppo|sac``: train an agent on ``ACLDBeam-v1``.

Writes to ``--out`` (default ``runs/<algo>-<load case>-s<seed>``): the agent as
``policy.npz`` + ``metadata.json`` (loads with :meth:`train.agent.TrainedAgent.load`;
the metadata records the command, seed, config, versions, the teacher if any, and the
observation fingerprint), ``best/`` (the same for the best checkpoint on the thesis
cases), ``model.zip`` + ``vecnormalize.pkl`` (SB3's files, to resume training),
``checkpoints/``, ``tb/`` (TensorBoard) and ``learning_curve.csv``.

No teacher by default: ``train/ppo.yaml`` and ``train/sac.yaml`` learn from the env's
reward alone. ``train/ppo_dagger.yaml`` and ``train/sac_dagger.yaml`` (``--config``)
first distill the MPC into the actor by DAgger; the output and metadata say so.
"""

from __future__ import annotations

import argparse
import platform
import shlex
import sys
import time
from pathlib import Path

from acld_gym.util.atomic import check_writable
from acld_gym.util.validate import arg_type

from .config import ALGOS, TrainConfig, algo_class, load_config, parse_load_case

__all__ = ["main", "train", "make_model", "versions", "parse_load_case"]


def versions() -> dict[str, str]:
    import gymnasium
    import numpy
    import scipy
    import stable_baselines3
    import torch

    import acld_gym

    return {"python": platform.python_version(), "acld_gym": acld_gym.__version__,
            "gymnasium": gymnasium.__version__, "stable_baselines3": stable_baselines3.__version__,
            "torch": torch.__version__, "numpy": numpy.__version__, "scipy": scipy.__version__}


def make_model(cfg: TrainConfig, venv, seed: int, **kwargs):
    """The (untrained) SB3 model of ``cfg`` on ``venv``: the config's keyword
    arguments with its ``features`` extractor, CPU, seeded; ``kwargs`` add to them."""
    model_kwargs = dict(cfg.model)
    policy = model_kwargs.pop("policy")
    if cfg.features is not None:
        from .features import FEATURES

        model_kwargs["policy_kwargs"] = {**model_kwargs.get("policy_kwargs", {}),
                                         "features_extractor_class": FEATURES[cfg.features]}
    return algo_class(cfg.algo)(policy, venv, seed=seed, device="cpu",
                                 **{**model_kwargs, **kwargs})


def train(cfg: TrainConfig, seed: int, out: Path, progress_bar: bool = False,
          backend: str = "native", command: str | None = None, verbose: int = 0):
    """Train ``cfg`` with ``seed`` into ``out``; returns the SB3 model.

    Repeatable on one machine: the env's sub-env seeds, the algorithm's seed and
    torch (one thread) are all set from ``seed``.
    """
    import torch
    from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback

    from .agent import MODEL_FILE, STATS_FILE
    from .callbacks import PhysicsRolloutLogger, make_eval_callback
    from .vec import make_vec_env

    torch.set_num_threads(1)  # small networks: threads cost more than they give, and
    # a single thread keeps runs bit-for-bit repeatable
    out.mkdir(parents=True, exist_ok=True)
    venv = make_vec_env(cfg, seed, backend=backend)
    model = make_model(cfg, venv, seed, verbose=verbose, tensorboard_log=str(out / "tb"))
    distilled = None
    if cfg.distill is not None:
        from .distill import distill

        t0 = time.perf_counter()
        distilled = {"history": distill(model, venv, cfg.distill_config, seed=seed),
                     "seconds": round(time.perf_counter() - t0, 1)}
    callbacks = CallbackList([
        make_eval_callback(cfg, out, cfg.n_envs),
        CheckpointCallback(max(cfg.checkpoint_freq // cfg.n_envs, 1), str(out / "checkpoints"),
                           name_prefix=cfg.algo, save_vecnormalize=True),
        PhysicsRolloutLogger(),
    ])
    t0 = time.perf_counter()
    model.learn(cfg.n_timesteps, callback=callbacks, progress_bar=progress_bar,
                tb_log_name=cfg.algo)
    seconds = time.perf_counter() - t0
    # SB3's own files, to resume training (pickled: load them only from trusted sources)
    model.save(str(out / MODEL_FILE))
    venv.save(str(out / STATS_FILE))
    meta = {"algo": cfg.algo, "seed": seed, "command": command, "config": cfg.as_dict(),
            "training": cfg.training, "teacher": cfg.teacher, "residual": cfg.residual,
            "timesteps": int(model.num_timesteps), "train_seconds": round(seconds, 1),
            "distill": distilled, "backend": backend, "versions": versions()}
    export_run(out, cfg, meta, model, venv)
    venv.close()
    return model


def export_run(out: Path, cfg: TrainConfig, meta: dict, model=None, venv=None) -> None:
    """Write the run's agent (``policy.npz`` + ``metadata.json``) for the final model and,
    if the ``EvalCallback`` saved one, for the best checkpoint in ``out/best``. ``meta``
    gets the env and its observation fingerprint. ``model``/``venv`` default to the run's
    own ``model.zip``/``vecnormalize.pkl`` (written by this package: trusted)."""
    import pickle

    import gymnasium as gym

    from acld_gym.envs.fingerprint import observation_fingerprint

    from .agent import MODEL_FILE, STATS_FILE, TrainedAgent, export_sb3

    env_meta = {"id": "ACLDBeam-v1", "kwargs": {"mesh": cfg.mesh}}
    probe = gym.make(env_meta["id"], **env_meta["kwargs"])  # the observation it trained on
    meta = dict(meta, env=env_meta, observation=observation_fingerprint(probe))
    probe.close()

    def stats(path: Path):
        if not path.is_file():
            return None
        with path.open("rb") as fh:  # this run's own file (trusted); SB3's format
            return pickle.load(fh)

    if model is None:
        model = algo_class(cfg.algo).load(str(out / MODEL_FILE), device="cpu")
        venv = stats(out / STATS_FILE)
    TrainedAgent(export_sb3(model, venv), meta, cfg.algo).save(out)
    best = out / "best"
    if (best / "best_model.zip").is_file():
        best_model = algo_class(cfg.algo).load(str(best / "best_model.zip"), device="cpu")
        TrainedAgent(export_sb3(best_model, stats(best / STATS_FILE) or venv), meta,
                     cfg.algo).save(best)


def _load_case_arg(text: str):
    """``--load-case`` value: 1, 2, 3 or ``random`` (:func:`train.config.parse_load_case`)."""
    try:
        return parse_load_case(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


#: Seeds: numpy's legacy seeding (used by SB3) takes integers below 2**32.
MAX_SEED = 2**32 - 1
_positive_int = arg_type(int, 1, 10**12)
_seed = arg_type(int, 0, MAX_SEED)
_param_noise = arg_type(float, 0.0)  # its bound (per mesh) is checked by TrainConfig


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m train", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("algo", choices=ALGOS, help="the algorithm")
    p.add_argument("--load-case", type=_load_case_arg, default=None,
                   help="training loads: 1, 2, 3 or random (default: the config's)")
    p.add_argument("--timesteps", type=_positive_int, default=None,
                   help="env steps in total (default: the config's n_timesteps)")
    p.add_argument("--seed", type=_seed, default=0, help=f"seed in [0, {MAX_SEED}] (default 0)")
    p.add_argument("--n-envs", type=_positive_int, default=None,
                   help="sub-envs of the batched env (default: the config's)")
    p.add_argument("--param-noise", type=_param_noise, default=None,
                   help="per-episode parameter randomization (default: the config's)")
    p.add_argument("--config", metavar="YAML", default=None,
                   help="hyperparameter file (default: train/<algo>.yaml)")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="output directory (default: runs/<algo>-<case>-s<seed>)")
    p.add_argument("--backend", choices=("native", "subproc"), default="native",
                   help="native batched env (default) or SB3 SubprocVecEnv")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        cfg = load_config(args.algo, args.config).with_overrides(
            load_case=args.load_case, n_timesteps=args.timesteps, n_envs=args.n_envs,
            param_noise=args.param_noise)
    except (OSError, ValueError) as exc:
        parser.error(str(exc))  # exit status 2, no traceback
    out = Path(args.out or f"runs/{cfg.algo}-{cfg.load_case}-s{args.seed}")
    if out.exists() and not out.is_dir():
        parser.error(f"--out: {str(out)!r} exists and is not a directory")
    try:  # before any training: an unusable --out fails now, not after the run
        check_writable(out / "metadata.json", "--out")
    except ValueError as exc:
        parser.error(str(exc))
    command = "python -m train " + " ".join(shlex.quote(a) for a in
                                            (sys.argv[1:] if argv is None else argv))
    print(f"training {cfg.algo.upper()} {cfg.training}: "
          + ("no teacher -- it learns from the env's observation and reward only"
             if cfg.teacher is None else
             f"the actor first imitates the {cfg.teacher.upper()} (DAgger, opt-in via the "
             "config's distill:), then RL"))
    train(cfg, args.seed, out, progress_bar=not args.no_progress, backend=args.backend,
          command=command)
    print(f"wrote {out}/: policy.npz + metadata.json (the agent), best/ (the same for the best "
          "checkpoint), model.zip + vecnormalize.pkl (to resume training), learning_curve.csv, "
          "tb/")
    return 0
