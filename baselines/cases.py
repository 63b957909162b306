"""Every reference on named load cases: one seeded episode per case and policy, plus the
clairvoyant bound of the same load and plant, as rows of metrics (:func:`evaluate`), and
their means over episodes (:func:`mean_rows`). The primitives of ``python -m
baselines.evaluate`` (:mod:`baselines.evaluate`, the CLI and its tables) and of
``train.compare``; one episode is :func:`baselines.evaluation.rollout.rollout`."""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.physics.loads import THESIS_CASES
from acld_gym.util.progress import Progress

from .evaluation.rollout import EvalRow, bound_episode, metrics_row, rollout
from .policies import policies_for

__all__ = ["episode_rows", "evaluate", "mean_rows"]


def episode_rows(
    policies: dict,
    case,
    seed: int = 0,
    env_kwargs: dict | None = None,
    episodes: dict | None = None,
    progress: Progress | None = None,
    episode: str = "",
) -> list[EvalRow]:
    """One episode of ``case`` (seeded: load, parameters, sensor noise) per policy, plus
    the clairvoyant bound for the same load and plant; fills ``episodes`` if given and
    reports each policy's episode to ``progress`` (labelled with ``episode``)."""
    env = ACLDBeamEnv(load_case=case, **(env_kwargs or {}))
    rows = []
    for name, pol in policies.items():
        if progress is not None:
            progress.stage(f"case {case} · {name}{episode}")
        ep = rollout(pol, env, seed=seed)
        rows.append(metrics_row(case, name, ep))
        if episodes is not None:
            episodes[case, name] = ep
    if progress is not None:
        progress.stage(f"case {case} · bound{episode}")
    env.reset(seed=seed)
    ep = bound_episode(env)
    rows.append(metrics_row(case, "bound", ep))
    if episodes is not None:
        episodes[case, "bound"] = ep
    return rows


def evaluate(
    policies: dict | None = None,
    cases=THESIS_CASES,
    seed: int = 0,
    env_kwargs: dict | None = None,
    episodes: dict | None = None,
    quiet: bool = True,
) -> list[EvalRow]:
    """Rows for every (case, policy) plus the bound; fills ``episodes`` if given; a
    progress line on a terminal unless ``quiet``."""
    if policies is None:
        policies = policies_for(ACLDBeamEnv(**(env_kwargs or {})))
    with Progress(len(cases) * (len(policies) + 1), "evaluate", quiet) as progress:
        return [
            row
            for case in cases
            for row in episode_rows(policies, case, seed, env_kwargs, episodes, progress)
        ]


def mean_rows(rows: list[EvalRow], case) -> list[EvalRow]:
    """Per policy, the mean of each metric over ``rows`` (several episodes), labelled ``case``."""
    out = []
    for name in dict.fromkeys(r.policy for r in rows):
        sub = [asdict(r) for r in rows if r.policy == name]
        means = {
            k: float(np.mean([d[k] for d in sub])) for k in sub[0] if k not in ("case", "policy")
        }
        out.append(EvalRow(case=case, policy=name, **means))
    return out
