r"""One number per policy: where it sits between LQR (0) and the clairvoyant bound (1).

On each episode i of a published test set (:data:`acld_gym.benchmark.TEST_SETS`: random
loads, seeds disjoint from training and model selection),

.. math::

    s_i = \frac{ISE_{LQR,i} - ISE_i}{ISE_{LQR,i} - ISE_{bound,i}},

so LQR scores 0 on every episode by construction, the bound 1, a policy better than LQR
between the two, and one worse than LQR below 0 (passive: about -1 to -10). No causal
policy reaches 1: the bound knows the whole load in advance. The score is the
interquartile mean of the :math:`s_i` with a 95 % percentile bootstrap interval
(:mod:`acld_gym.util.stats`; the episodes are one stratum, the test set's single task).
The interquartile mean keeps the few episodes where LQR is already within a hair of the
bound, and the ratio ill-conditioned, from deciding the score.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import acld_gym
from acld_gym.benchmark import TEST_SETS, EvaluationSet, evaluation_set
from acld_gym.util.progress import Progress
from acld_gym.util.stats import iqm_with_ci

from .references import References, make_env, references

__all__ = [
    "Score",
    "episode_scores",
    "score_of",
    "score_policy",
    "policy_ises",
    "score_policies",
    "format_scores",
]


@dataclass(frozen=True)
class Score:
    """A policy's score on a test set (module docstring)."""

    iqm: float
    ci_low: float
    ci_high: float
    n_episodes: int
    test_set: str
    scores: np.ndarray
    """Per-episode scores :math:`s_i`."""
    ise: np.ndarray
    """Per-episode ISE of the policy [m^2 s]."""

    def as_dict(self) -> dict:
        """``{"iqm", "ci_low", "ci_high", "n_episodes", "test_set", "mean_ise"}`` (the mean
        ISE over the episodes [m^2 s], the ordering of the ISE tables)."""
        return {
            "iqm": self.iqm,
            "ci_low": self.ci_low,
            "ci_high": self.ci_high,
            "n_episodes": self.n_episodes,
            "test_set": self.test_set,
            "mean_ise": float(np.mean(self.ise)),
        }


def episode_scores(ise, lqr_ise, bound_ise) -> np.ndarray:
    """:math:`(ISE_{LQR} - ISE) / (ISE_{LQR} - ISE_{bound})` per episode; ``ValueError``
    unless every bound is strictly below its LQR (else the score is undefined)."""
    ise, lqr, bound = (np.asarray(a, dtype=float) for a in (ise, lqr_ise, bound_ise))
    if not ise.shape == lqr.shape == bound.shape or ise.ndim != 1:
        raise ValueError(
            f"ise, lqr_ise and bound_ise must be 1-D of one length, got "
            f"{ise.shape}, {lqr.shape}, {bound.shape}"
        )
    gap = lqr - bound
    if not np.all(np.isfinite(ise)) or not np.all(gap > 0):
        raise ValueError("ise must be finite and every bound strictly below LQR's ISE")
    return (lqr - ise) / gap


def score_of(ise, refs: References, reps: int = 2000, seed: int = 0) -> Score:
    """The score of per-episode ISE ``ise`` against ``refs`` (as many episodes)."""
    s = episode_scores(ise, refs.lqr_ise, refs.bound_ise)
    stats = iqm_with_ci(s, reps=reps, seed=seed)
    return Score(
        iqm=stats["iqm"],
        ci_low=stats["ci_low"],
        ci_high=stats["ci_high"],
        n_episodes=int(s.size),
        test_set=refs.name,
        scores=s,
        ise=np.asarray(ise, dtype=float),
    )


def policy_ises(
    policy,
    test: EvaluationSet,
    env_kwargs: dict | None = None,
    progress: Progress | None = None,
    label: str = "",
) -> np.ndarray:
    """The policy's ISE [m^2 s] on each episode of ``test`` (:func:`baselines.evaluate.rollout`)."""
    from baselines.evaluate import metrics_row, rollout

    env = make_env(test, env_kwargs)
    out = np.empty(len(test.seeds))
    for i, s in enumerate(test.seeds):
        if progress is not None:
            progress.stage(f"score{label} · episode {i + 1}/{len(test.seeds)}")
        out[i] = metrics_row("test", "policy", rollout(policy, env, seed=s)).ise
    return out


def score_policy(
    policy,
    env_id: str = acld_gym.ENV_ID,
    n_episodes: int | None = None,
    env_kwargs: dict | None = None,
    refs: References | None = None,
    quiet: bool = True,
) -> Score:
    """The score of ``policy`` (SB3 ``predict``, volts) on the test set of ``env_id`` (its
    first ``n_episodes``: a reduced run; None: all of it)."""
    test = evaluation_set(env_id)
    if n_episodes is not None:
        test = test.first(n_episodes)
    if refs is None:
        refs = references(test, env_kwargs, quiet=quiet)
    elif refs.seeds != test.seeds:
        raise ValueError(
            f"refs: references of other episodes than {test.name}'s first {len(test.seeds)}"
        )
    with Progress(len(test.seeds), "score", quiet) as progress:
        ise = policy_ises(policy, test, env_kwargs, progress)
    return score_of(ise, refs)


def score_policies(
    policies: dict,
    env_id: str = acld_gym.ENV_ID,
    n_episodes: int | None = None,
    env_kwargs: dict | None = None,
    quiet: bool = True,
) -> dict[str, Score]:
    """The score of each policy (name -> ``predict`` object) on the same test episodes, and
    of the bound itself (``"bound"``, 1 on every episode by construction)."""
    test = evaluation_set(env_id)
    if n_episodes is not None:
        test = test.first(n_episodes)
    refs = references(test, env_kwargs, quiet=quiet)
    out = {}
    with Progress(len(policies) * len(test.seeds), "score", quiet) as progress:
        for name, pol in policies.items():
            out[name] = score_of(policy_ises(pol, test, env_kwargs, progress, f" · {name}"), refs)
    out["bound"] = score_of(refs.bound_ise, refs)
    return out


def format_scores(scores: dict[str, Score], labels: dict | None = None) -> str:
    """The score table: per policy the IQM, its 95 % interval and the mean ISE over the test
    set relative to LQR's (the ordering the ISE tables use); a score on fewer episodes than
    the published test set's says so in the heading."""
    first = next(iter(scores.values()))
    ref = scores.get("lqr")
    lqr_mean = None if ref is None else float(np.mean(ref.ise))
    full = {t.name: len(t.seeds) for t in TEST_SETS.values()}.get(first.test_set)
    reduced = (
        ""
        if full is None or first.n_episodes >= full
        else f", the first of its {full}: a reduced score, not the published one"
    )
    head = (
        f"\nscore on {first.test_set} ({first.n_episodes} random loads{reduced}; LQR 0, "
        "clairvoyant bound 1): IQM of (ISE_LQR - ISE) / (ISE_LQR - ISE_bound), 95 % "
        "bootstrap CI"
    )
    trained = "" if labels is None else f" {'trained':>22}"
    out = [
        head,
        f"{'policy':>12}{trained} {'IQM':>8} {'CI low':>8} {'CI high':>8} {'mean ISE / LQR':>15}",
    ]
    for name, s in scores.items():
        rel = "-" if lqr_mean is None else f"{np.mean(s.ise) / lqr_mean:.4f}"
        label = "" if labels is None else f" {labels.get(name, ''):>22}"
        out.append(f"{name:>12}{label} {s.iqm:8.4f} {s.ci_low:8.4f} {s.ci_high:8.4f} {rel:>15}")
    return "\n".join(out)
