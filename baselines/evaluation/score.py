r"""One number per policy, score v2: where it sits between the passive beam (0) and the
clairvoyant bound (1).

On each episode i of a published test set (:data:`baselines.evaluation.seeds.TEST_SETS`: random
loads, seeds disjoint from training and model selection),

.. math::

    s_i = \frac{ISE_{passive,i} - ISE_i}{ISE_{passive,i} - ISE_{bound,i}},

so the passive beam (no voltage) scores 0 on every episode, the bound 1, and a policy that
makes the tip worse than no control at all scores below 0. Both anchors are fixed: neither
moves when a reference is redesigned, on every level (the bound has the level's actuator
inside, :func:`baselines.evaluation.rollout.bound_episode`). No causal policy reaches 1: the bound
knows the whole load in advance. The score is the interquartile mean of the :math:`s_i`
with a 95 % percentile bootstrap interval (:mod:`acld_gym.util.stats`; the episodes are one
stratum, the test set's single task).

Score v1 (before acld-gym 0.20.0) anchored 0 on the thesis's LQR, which is a delay-free design:
under the lab rig's period of delay it limit-cycles, so v1 scores are not comparable with
these (:data:`SCORE_VERSION`; every table that prints a score names its version). The
mean ISE relative to the thesis LQR's stays beside the score as the thesis-facing column.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import acld_gym
from acld_gym.util.progress import Progress
from acld_gym.util.stats import iqm_with_ci

from .references import References, make_env, references
from .rollout import metrics_row, rollout
from .seeds import TEST_SETS, EvaluationSet, evaluation_set

__all__ = [
    "SCORE_VERSION",
    "SCORE_NAME",
    "ScoreUndefined",
    "Score",
    "episode_scores",
    "score_of",
    "score_policy",
    "policy_ises",
    "score_policies",
    "format_scores",
]


#: Version of the score's definition (module docstring): 2, anchored on passive and bound.
SCORE_VERSION = 2
#: How tables and JSON records name it.
SCORE_NAME = f"score v{SCORE_VERSION}"


class ScoreUndefined(ValueError):
    """The score of an episode whose bound is not strictly below the passive beam's ISE
    (or of non-finite ISE): it has no anchors there."""


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
    thesis_lqr_ise: np.ndarray | None = None
    """Per-episode ISE of the thesis LQR on the same episodes [m^2 s] (the references')."""

    @property
    def ise_rel_thesis_lqr(self) -> float:
        """The mean ISE over the episodes relative to the thesis LQR's (the thesis-facing
        column; NaN without the LQR's)."""
        if self.thesis_lqr_ise is None:
            return float("nan")
        return float(np.mean(self.ise) / np.mean(self.thesis_lqr_ise))

    def as_dict(self) -> dict:
        """``{"version", "iqm", "ci_low", "ci_high", "n_episodes", "test_set", "mean_ise",
        "ise_rel_thesis_lqr"}`` (``version`` :data:`SCORE_VERSION`; the mean ISE over the
        episodes [m^2 s], the ordering of the ISE tables, and relative to the thesis LQR's;
        None without it)."""
        rel = self.ise_rel_thesis_lqr
        return {
            "version": SCORE_VERSION,
            "iqm": self.iqm,
            "ci_low": self.ci_low,
            "ci_high": self.ci_high,
            "n_episodes": self.n_episodes,
            "test_set": self.test_set,
            "mean_ise": float(np.mean(self.ise)),
            "ise_rel_thesis_lqr": rel if np.isfinite(rel) else None,
        }


def episode_scores(ise, passive_ise, bound_ise) -> np.ndarray:
    """:math:`(ISE_{passive} - ISE) / (ISE_{passive} - ISE_{bound})` per episode;
    ``ValueError`` if the arrays are not 1-D of one length, :class:`ScoreUndefined` unless
    every ISE is finite and every bound strictly below its passive ISE."""
    ise, passive, bound = (np.asarray(a, dtype=float) for a in (ise, passive_ise, bound_ise))
    if not ise.shape == passive.shape == bound.shape or ise.ndim != 1:
        raise ValueError(
            f"ise, passive_ise and bound_ise must be 1-D of one length, got "
            f"{ise.shape}, {passive.shape}, {bound.shape}"
        )
    gap = passive - bound
    if not (np.all(np.isfinite(ise)) and np.all(np.isfinite(gap))):
        raise ScoreUndefined("the score needs finite ISE (policy, passive and bound)")
    if not np.all(gap > 0):
        bad = int(np.argmin(gap))
        raise ScoreUndefined(
            f"the score is undefined where the bound is not below the passive ISE "
            f"(episode {bad}: passive {passive[bad]:.4g}, bound {bound[bad]:.4g} m^2 s)"
        )
    return (passive - ise) / gap


def score_of(ise, refs: References, reps: int = 2000, seed: int = 0) -> Score:
    """The score of per-episode ISE ``ise`` against ``refs`` (as many episodes)."""
    s = episode_scores(ise, refs.passive_ise, refs.bound_ise)
    stats = iqm_with_ci(s, reps=reps, seed=seed)
    return Score(
        iqm=stats["iqm"],
        ci_low=stats["ci_low"],
        ci_high=stats["ci_high"],
        n_episodes=int(s.size),
        test_set=refs.name,
        scores=s,
        ise=np.asarray(ise, dtype=float),
        thesis_lqr_ise=refs.lqr_ise,
    )


def policy_ises(
    policy,
    test: EvaluationSet,
    env_kwargs: dict | None = None,
    progress: Progress | None = None,
    label: str = "",
) -> np.ndarray:
    """The policy's ISE [m^2 s] on each episode of ``test``
    (:func:`baselines.evaluation.rollout.rollout`)."""
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
    of the bound itself (``"bound"``, 1 on every episode: its cached ISE are the anchors;
    tests/baselines/evaluation/test_score.py replays its voltages through the env to check
    that the path that scores a policy gives it 1 too)."""
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
    """The score table (score v2): per policy the IQM, its 95 % interval and the mean ISE
    over the test set relative to the thesis LQR's (the thesis-facing column, and the
    ordering the ISE tables use); a score on fewer episodes than the
    published test set's says so in the heading. ``labels``: a column of what each policy
    is (its kind, how it was trained)."""
    first = next(iter(scores.values()))
    full = {t.name: len(t.seeds) for t in TEST_SETS.values()}.get(first.test_set)
    reduced = (
        ""
        if full is None or first.n_episodes >= full
        else f", the first of its {full}: a reduced score, not the published one"
    )
    head = (
        f"\nscore on {first.test_set} ({SCORE_NAME}: {first.n_episodes} random loads"
        f"{reduced}; passive 0, clairvoyant bound 1): IQM of (ISE_passive - ISE) / (ISE_passive - "
        "ISE_bound), 95 % bootstrap CI; the last column is the thesis-facing one"
    )
    width = 12 if labels is None else max(12, *(len(str(v)) for v in labels.values()))
    label_head = "" if labels is None else f" {'what it is':>{width}}"
    out = [
        head,
        f"{'policy':>12}{label_head} {'IQM':>8} {'CI low':>8} {'CI high':>8} "
        f"{'mean ISE / thesis LQR':>22}",
    ]
    for name, s in scores.items():
        rel = s.ise_rel_thesis_lqr
        rel = f"{rel:.4f}" if np.isfinite(rel) else "-"
        label = "" if labels is None else f" {labels.get(name, ''):>{width}}"
        out.append(f"{name:>12}{label} {s.iqm:8.4f} {s.ci_low:8.4f} {s.ci_high:8.4f} {rel:>22}")
    return "\n".join(out)
