"""The leaderboard's numbers of one policy: its score, its ISE relative to the thesis LQR per
case and its effort after settling, each by the package's own evaluators.

* references (:func:`reference_entries`): the policies of
  :func:`baselines.marks.level_references` scored together on the level's test set
  (:func:`baselines.evaluation.score.score_policies`, its cached anchors), their mean ISE per
  case by :func:`baselines.evaluation.ise.rollout_ise` and the clairvoyant bound's by
  :func:`baselines.evaluation.ise.bound_ise` on the same episodes;
* a trained agent (:func:`agent_entry`): :func:`train.scoring.score`, the function that
  scores any policy;
* the effort of either (:func:`settled_effort`): one episode of thesis cases 1 and 2 (seed
  0), :func:`baselines.analysis.effort.effort` after the tip has settled.
"""

from __future__ import annotations

from baselines.analysis.effort import effort, settled_from
from baselines.evaluation.ise import bound_ise, case_env, eval_episodes, rollout_ise
from baselines.evaluation.rollout import bound_episode, rollout
from baselines.evaluation.score import score_policies
from baselines.evaluation.seeds import HELDOUT_SEEDS

from ..scoring import score
from .schema import CASES, EFFORT_CASES

__all__ = [
    "case_episodes",
    "settled_effort",
    "bound_effort",
    "bound_ise",
    "reference_entries",
    "agent_entry",
    "score_fields",
]


def case_episodes(episodes: int | None) -> dict:
    """``{case: seeds}`` of the ISE / thesis LQR columns: seed 0 of thesis cases 1, 2, 3
    and the held-out random loads (all 20; with a reduced run of ``episodes`` test
    episodes, at most that many, as :func:`train.scoring.score` takes them)."""
    n = len(HELDOUT_SEEDS) if episodes is None else min(len(HELDOUT_SEEDS), episodes)
    return eval_episodes(n)


def _effort(ep, case: str) -> dict:
    dt = float(ep.t[1] - ep.t[0])
    e = effort(ep.voltage, ep.y, dt, settled_from(int(case)))
    return {
        "settled_rms_voltage_V": e.settled_rms_voltage_V,
        "settled_limit_fraction": e.limit_fraction,
    }


def settled_effort(policy, env_id: str) -> dict:
    """``{case: {"settled_rms_voltage_V", "settled_limit_fraction"}}`` of ``policy`` (SB3
    ``predict`` in volts) on thesis cases 1 and 2, seed 0
    (:func:`baselines.evaluation.rollout.rollout`)."""
    return {c: _effort(rollout(policy, case_env(env_id, int(c)), seed=0), c) for c in EFFORT_CASES}


def _bound_episode(env_id: str, case, seed: int):
    env = case_env(env_id, case)
    env.reset(seed=seed)
    return bound_episode(env)


def bound_effort(env_id: str) -> dict:
    """:func:`settled_effort` of the clairvoyant bound (its patch voltages)."""
    return {c: _effort(_bound_episode(env_id, int(c), 0), c) for c in EFFORT_CASES}


def score_fields(score) -> dict:
    """The ``SCORE`` fields (:mod:`train.leaderboard.schema`) of a
    :class:`baselines.evaluation.score.Score`."""
    d = score.as_dict()
    return {k: d[k] for k in ("version", "iqm", "ci_low", "ci_high", "n_episodes", "test_set")}


def _ratios(ise: dict, lqr: dict) -> dict:
    return {str(c): float(ise[c] / lqr[c]) for c in ise}


def reference_entries(
    env_id: str, policies: dict, kinds: dict, episodes: int | None = None, quiet: bool = True
) -> dict:
    """``{name: ENTRY}`` (:mod:`train.leaderboard.schema`) of every policy of
    ``policies`` (name -> SB3 ``predict`` in volts; it must hold ``"lqr"``, the thesis
    LQR, the yardstick of the ISE columns) and of the clairvoyant bound; ``kinds``: what each is
    (:func:`baselines.marks.mark_labels`); ``episodes``: the first that many test episodes
    (None: all: the published score)."""
    if "lqr" not in policies:
        raise ValueError("policies must hold the thesis LQR ('lqr'): the ISE columns' yardstick")
    scores = score_policies(policies, env_id, episodes, quiet=quiet)
    cases = case_episodes(episodes)
    ise = {name: rollout_ise(pol, env_id, cases) for name, pol in policies.items()}
    ise["bound"] = bound_ise(env_id, cases)
    effort = {name: settled_effort(pol, env_id) for name, pol in policies.items()}
    effort["bound"] = bound_effort(env_id)
    return {
        name: {
            "kind": kinds.get(name, "reference"),
            "score": score_fields(scores[name]),
            "ise_rel_lqr": _ratios(ise[name], ise["lqr"]),
            "effort": effort[name],
        }
        for name in scores
    }


def agent_entry(agent, env_id: str, episodes: int | None = None) -> dict:
    """The measured part of a ``SEED`` (:mod:`train.leaderboard.schema`) of a trained agent
    (:class:`train.agent.TrainedAgent`): :func:`train.scoring.score` and
    :func:`settled_effort`."""
    s = score(agent, env_id, episodes=episodes)
    rel = {str(c): float(v) for c, v in s.ise_rel_lqr.items()}
    if sorted(rel) != sorted(CASES):
        raise ValueError(f"train.scoring.score gave the cases {sorted(rel)}, expected {CASES}")
    return {
        "score": score_fields(s.score),
        "ise_rel_lqr": rel,
        "effort": settled_effort(agent, env_id),
    }
