"""Trials of the benchmark: an algorithm's YAML config, one (config, seed) run with its
learning curve and final evaluation, the saved agent directory, and many runs one
after the other or as Ray Tune trials."""

from __future__ import annotations

import json
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

from acld_gym.envs.fingerprint import observation_fingerprint
from acld_gym.util.atomic import write_text

from ..agent import CURVE_FILE, ActorProgram, TrainedAgent, export_sb3, linear_program, versions
from ..config import CONFIG_DIR, TrainConfig
from .evaluate import (
    DEFAULT_ENV_ID,
    OBJECTIVE_LOADS,
    batched_ise,
    eval_episodes,
    rollout_ise,
    validation_cost,
    validation_seeds,
)
from .progress import Progress

__all__ = [
    "CONFIG_DIR",
    "DEFAULT_ALGOS",
    "REFERENCES",
    "run_trial",
    "agent_dir",
    "policy_program",
    "save_agent",
    "run_trials",
    "trained_line",
    "ray_available",
]

#: The benchmark's algorithms (``train/recipes/<name>.yaml``).
DEFAULT_ALGOS = ("vrs", "ars", "ppo", "sac", "tqc")
REFERENCES = ("lqr", "smc", "mpc", "bound")


def run_trial(
    name: str,
    config: dict,
    seed: int,
    env_id: str = DEFAULT_ENV_ID,
    random_episodes: int = 20,
    out: str | Path | None = None,
    command: str | None = None,
    workers: int = 1,
    quiet: bool = False,
) -> tuple[dict, object]:
    """Train one (config, seed) and evaluate it; returns ``(record, policy)``: the trial's
    record (JSON-able: the learning curve, mean ISE per case at each evaluation, batched --
    with restarts, the returned run's, ``train_algo``;
    the final ISE per case, single-env rollouts; the training wall time, evaluations
    excluded; the final policy's ``validation_cost``, the env's own objective on the
    first :data:`train.core.evaluate.OBJECTIVE_LOADS` validation loads; the command) and
    the final policy. With ``out``, the policy is saved as an
    agent in :func:`agent_dir`. ``workers``: how many of the trial's runs (``restarts``)
    train at once (:func:`train.core.algos.train_algo`: the same result, in less time).

    On the console, lines labelled ``<name> s<seed>``
    (:class:`train.core.progress.Progress`): one per evaluation with the current
    validation score (none with ``quiet``), the retry threshold and every retry with its
    reason, which the record keeps too (``retries``, ``[]`` when the first run sufficed or
    there is one)."""
    # torch and the training algorithms (SB3) are slow to import: only a run needs them
    import torch

    from .algos import train_algo

    torch.set_num_threads(1)
    cfg = TrainConfig.from_dict(config)
    episodes = eval_episodes(random_episodes)
    t0 = time.perf_counter()
    progress = Progress(f"{name} s{seed}", quiet)
    policy, record = train_algo(cfg, seed, env_id, CaseISE(env_id, episodes), workers, progress)
    wall = time.perf_counter() - t0
    final = rollout_ise(policy, env_id, episodes)
    cost = validation_cost(policy, env_id, validation_seeds(OBJECTIVE_LOADS))
    rec = {
        "name": name,
        "algo": cfg.algo,
        "seed": int(seed),
        "env_id": env_id,
        "config": config,
        "random_episodes": int(random_episodes),
        "command": command
        or f"python -m train.benchmark --config {name} --seeds {seed} --env-id {env_id}",
        "budget": cfg.budget,
        "steps": int(record.get("steps", 0)),
        "train_seconds": float(record["train_seconds"]),
        "train_cpu_seconds": float(record.get("train_cpu_seconds", np.nan)),
        "wall_seconds": wall,
        "final_ise": {str(c): v for c, v in final.items()},
        "validation_cost": cost,
        "runs": len(record.get("restarts", {}).get("runs", [None])),
        "retries": record.get("restarts", {}).get("retries", []),
        "curve": record["curve"],
        "record": {
            k: v
            for k, v in record.items()
            if k not in ("train_seconds", "train_cpu_seconds", "curve")
        },
    }
    if out is not None:
        save_agent(policy, rec, agent_dir(out, name, seed))
    return rec, policy


class CaseISE:
    """A point of a trial's learning curve: the policy's ISE per case (thesis cases and the
    random set, batched rollouts), ``{"ise": {case: ise}}``; a class, not a closure, so
    that runs in worker processes can take it along."""

    def __init__(self, env_id: str, episodes: dict):
        self.env_id = env_id
        self.episodes = episodes

    def __call__(self, steps: int, policy) -> dict:
        ise = batched_ise(policy, self.env_id, self.episodes)
        return {"ise": {str(c): v for c, v in ise.items()}}


def trained_line(rec: dict) -> str:
    """What a trial's record says of its training in one line: the time, and with several
    runs how many it took and why (``trained in 412 s, 3 runs (2 retries: ...)``)."""
    text = f"trained in {rec['train_seconds']:.0f} s"
    runs, retries = rec.get("runs", 1), rec.get("retries", [])
    if runs > 1:
        why = f" ({len(retries)} retr{'y' if len(retries) == 1 else 'ies'}: " if retries else ""
        text += f", {runs} runs{why}{'; '.join(retries)}{')' if retries else ''}"
    return text


def trial_path(out: Path, name: str, seed: int) -> Path:
    return out / "trials" / f"{name}-s{seed}.json"


def agent_dir(out: Path, name: str, seed: int) -> Path:
    """Where a trial's final policy is saved as an agent (:class:`train.agent.TrainedAgent`)."""
    return Path(out) / "agents" / f"{name}-s{seed}"


def policy_program(policy):
    """A trained benchmark policy as a :class:`train.agent.ActorProgram` (numpy arrays and
    a JSON list of operations: loading it never runs code)."""
    # the trained policies' classes import torch (slow): only an export needs them
    from .sb3_inference import SB3Policy
    from .search import LinearDirectionActor

    if isinstance(policy, LinearDirectionActor):
        return linear_program(policy.theta, policy.transform, policy.features)
    if isinstance(policy, SB3Policy):  # direction features (an env wrapper), then VecNormalize
        prog = export_sb3(policy.model, policy.obs_norm)
        if policy.features == "direction":
            prog = ActorProgram([{"op": "direction"}, *prog.ops], prog.arrays)
        return prog
    raise TypeError(f"cannot export a {type(policy).__name__}")


def save_agent(
    policy, rec: dict, directory: str | Path, files: dict[str, str] | None = None
) -> Path:
    """Save a trial's final policy as an agent directory (``policy.npz``,
    ``metadata.json`` with how it was trained -- ``"from scratch"`` unless the config has
    a teacher or controller knowledge --, the command, config, budget, times and the
    observation fingerprint of the env it was trained on, ``learning_curve.csv`` and the
    text ``files``), the folder written whole (:meth:`train.agent.TrainedAgent.save`)."""
    cfg = TrainConfig.from_dict(rec["config"])
    memory = getattr(policy, "commands", None)  # an SB3Policy trained with observe_commands
    probe = gym.make(rec["env_id"])
    meta = {
        "algo": rec["algo"],
        "seed": rec["seed"],
        "benchmark": rec["name"],
        "command": rec["command"],
        "config": rec["config"],
        "training": cfg.training,
        "teacher": cfg.teacher,
        "residual": cfg.residual,
        "action_headroom": cfg.action_headroom,
        "distill": rec["record"].get("distill"),
        "timesteps": rec["steps"],
        "budget": rec["budget"],
        "train_seconds": round(rec["train_seconds"], 1),
        "train_cpu_seconds": round(rec["train_cpu_seconds"], 1),
        "final_ise": rec["final_ise"],
        "versions": versions(),
        "env": {"id": rec["env_id"], "kwargs": {}},
        "commands": None if memory is None else memory.as_dict(),
        "observation": observation_fingerprint(probe),
    }
    probe.close()
    # its learning curve on the thesis cases and the random set, batched evaluations
    lines = ["timesteps,case,ise"] + [
        f"{p['steps']},{c},{ise!r}" for p in rec["curve"] for c, ise in p["ise"].items()
    ]
    texts = {CURVE_FILE: "\n".join(lines) + "\n", **(files or {})}
    return TrainedAgent(policy_program(policy), meta, rec["algo"]).save(Path(directory), texts)


def _tune_trainable(config: dict) -> None:  # pragma: no cover - runs inside Ray workers
    from ray import tune  # Ray is optional (the extra "ray")

    kwargs = json.loads(config["trial"])
    out = Path(kwargs["out"])
    rec, _ = run_trial(**kwargs)
    # written here too, so that --resume finds the finished runs after an interruption (on a
    # cluster the driver writes them again from the reported results)
    write_text(trial_path(out, rec["name"], rec["seed"]), json.dumps(rec) + "\n")
    tune.report({"train_seconds": rec["train_seconds"], "record": json.dumps(rec)})


def _trial_cpus(config: dict):  # pragma: no cover - called by Ray Tune
    """A Ray trial's resources: one CPU per run it trains at once (``workers``)."""
    from ray.tune import PlacementGroupFactory  # Ray is optional (the extra "ray")

    return PlacementGroupFactory([{"CPU": json.loads(config["trial"])["workers"]}])


def init_ray(address: str | None, num_cpus: int) -> None:
    """Connect to the Ray cluster at ``address``, or start a local one with ``num_cpus``;
    a session already running in this process (an earlier benchmark or sweep) is reused."""
    import ray  # optional (the extra "ray")

    if not ray.is_initialized():
        ray.init(address=address) if address else ray.init(num_cpus=num_cpus)


def run_trials(
    trials: list[dict],
    out: Path,
    backend: str = "local",
    num_cpus: int = 2,
    address: str | None = None,
    workers: int = 1,
) -> list[dict]:
    """Run ``trials`` (keyword arguments of :func:`run_trial`) and write each record to
    ``out/trials/``; ``backend="ray"`` runs them as Ray Tune trials (``workers`` CPUs each:
    a trial trains that many of its runs at once)."""
    records = []
    if not trials:  # nothing to train (e.g. --resume --no-train): no Ray start either
        return records
    # a trial with fewer runs than workers takes one CPU per run
    trials = [
        {**t, "workers": min(workers, TrainConfig.from_dict(t["config"]).restarts)} for t in trials
    ]
    if backend == "local":
        for t in trials:
            rec, _ = run_trial(**t, out=out)
            write_text(trial_path(out, rec["name"], rec["seed"]), json.dumps(rec) + "\n")
            print(f"  {rec['name']} seed {rec['seed']}: {trained_line(rec)}", flush=True)
            records.append(rec)
        return records
    from ray import tune  # optional (the extra "ray")

    init_ray(address, num_cpus)
    # one grid point per run: run_trial's arguments as JSON text (Tune's loggers sort config
    # keys, and the load weights mix int and str keys)
    tuner = tune.Tuner(
        tune.with_resources(_tune_trainable, _trial_cpus),
        param_space={
            "trial": tune.grid_search(
                [json.dumps({**t, "out": str(out.resolve())}) for t in trials]
            )
        },
        tune_config=tune.TuneConfig(trial_dirname_creator=lambda t: f"trial_{t.trial_id}"),
        run_config=tune.RunConfig(
            storage_path=str((out / "ray").resolve()), name="benchmark", verbose=0
        ),
    )
    results = tuner.fit()
    for res in results:
        if res.error is not None:
            raise RuntimeError(f"a Ray trial failed: {res.error}")
        rec = json.loads(res.metrics["record"])
        write_text(trial_path(out, rec["name"], rec["seed"]), json.dumps(rec) + "\n")
        records.append(rec)
    return records


def ray_available() -> bool:
    try:
        import ray  # noqa: F401
        from ray import tune  # noqa: F401
    except ImportError:
        return False
    return True
