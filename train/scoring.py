r"""Score any policy in one call: :func:`score`.

A policy trained with any library on a level of this benchmark is scored the way the
package scores its own agents and references:

* its **score** (score v2, :mod:`baselines.evaluation.score`): the interquartile mean over
  the level's published test set (:data:`acld_gym.test_sets.TEST_SETS`) of
  :math:`(ISE_{passive} - ISE) / (ISE_{passive} - ISE_{bound})` per episode, with its 95 %
  bootstrap interval (passive 0, the clairvoyant bound 1);
* its **ISE relative to the thesis LQR** (the thesis-facing view of ``python -m
  train.compare``, :mod:`baselines.evaluation.ise`): the thesis cases 1, 2, 3
  (seed 0) and the held-out random loads (:data:`acld_gym.test_sets.HELDOUT_SEEDS`), the
  mean ISE per case divided by the LQR's designed on the same level.

The policy may be a stable-baselines3 model (with its ``VecNormalize`` statistics: the
observation normalization is applied, the reward normalization plays no part; a model
loaded with ``PPO.load(path)`` has no env, so it needs ``vec_normalize=`` the path of its
saved ``vecnormalize.pkl``, or ``False`` if it was trained without one), a
:class:`train.agent.TrainedAgent`, any object with SB3's
``predict(observation, state, episode_start, deterministic)`` (a stateful one, such as
SB3's recurrent policies or an engineer's LQG, gets its state back at every step and
``episode_start`` true at each episode's first), or a plain callable
``observation -> action``. ``wrappers`` are the single-env wrappers it was trained with,
innermost first (:mod:`acld_gym.wrappers`' ``UnitAction``, ``ObserveModes``,
``WhitenObservation``; Gymnasium's ``RescaleAction``, ``ClipAction``, ...): every episode
runs in the level's env wrapped by them, so the policy sees what it saw in training and
the env receives volts. A wrapper with running statistics (Gymnasium's
``NormalizeObservation``) is frozen (``update_running_mean = False``): give it the trained
statistics in its constructor callable.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import numpy as np

import acld_gym
from acld_gym.envs.presets import check_env_id
from acld_gym.util.validate import check_int, shown
from baselines.evaluation.ise import eval_episodes, lqr_ise
from baselines.evaluation.references import make_env, references
from baselines.evaluation.rollout import check_compatible, metrics_row, rollout
from baselines.evaluation.score import SCORE_VERSION, Score, score_of
from baselines.evaluation.seeds import HELDOUT_SEEDS, evaluation_set

from .scoring_inputs import as_policy, check_fits, wrap

__all__ = ["PolicyScore", "SCORE_LINE", "score", "policy_ise"]


@dataclass(frozen=True)
class PolicyScore:
    """What :func:`score` returns: the score on the test set and the ISE relative to the
    thesis LQR per case."""

    score: Score
    """The score (:class:`baselines.evaluation.score.Score`: IQM, interval, per-episode
    scores and ISE)."""
    ise: dict
    """Mean ISE [m^2 s] per case (1, 2, 3, ``"random"``) of the policy."""
    lqr_ise: dict
    """The same of the thesis LQR designed on the level."""
    env_id: str
    """The level."""

    @property
    def iqm(self) -> float:
        """The score: IQM over the test episodes (passive 0, bound 1)."""
        return self.score.iqm

    @property
    def ci(self) -> tuple[float, float]:
        """Its 95 % bootstrap interval."""
        return (self.score.ci_low, self.score.ci_high)

    @property
    def n_episodes(self) -> int:
        """Test episodes it is computed on (fewer than the set's: a reduced score)."""
        return self.score.n_episodes

    @property
    def test_set(self) -> str:
        """``"<env id>/test-v<version>"``."""
        return self.score.test_set

    @property
    def version(self) -> int:
        """The score's version (:data:`baselines.evaluation.score.SCORE_VERSION`)."""
        return SCORE_VERSION

    @property
    def ise_rel_lqr(self) -> dict:
        """``{case: ISE / ISE_LQR}`` on the thesis cases 1, 2, 3 and the held-out random
        loads (below 1: better than the thesis LQR)."""
        return {c: self.ise[c] / self.lqr_ise[c] for c in self.ise}

    def as_dict(self) -> dict:
        """JSON-able: ``{"env_id", "score": {...}, "ise_rel_lqr": {case: value}}`` (cases as
        strings)."""
        return {
            "env_id": self.env_id,
            "score": self.score.as_dict(),
            "ise_rel_lqr": {str(c): v for c, v in self.ise_rel_lqr.items()},
        }

    def __str__(self) -> str:
        full = len(evaluation_set(self.env_id).seeds)
        reduced = "" if self.n_episodes >= full else f" (first {self.n_episodes} of {full})"
        rel = ", ".join(f"{c}: {v:.3f}" for c, v in self.ise_rel_lqr.items())
        return (
            f"score v{self.version} on {self.test_set}{reduced}: {self.iqm:.4f} "
            f"[{self.ci[0]:.4f}, {self.ci[1]:.4f}]; ISE / thesis LQR {rel}"
        )


#: The line ``str(PolicyScore)`` prints, as a pattern: groups ``version``, ``id``, ``set``
#: (``test-vN``), ``n`` (the episodes of a reduced score, else None), ``iqm``, ``lo``,
#: ``hi`` and ``c1``, ``c2``, ``c3``, ``cr`` (ISE / thesis LQR on cases 1, 2, 3, random).
SCORE_LINE = re.compile(
    r"score v(?P<version>\d+) on (?P<id>[^/\s]+)/(?P<set>test-v\d+)"
    r"(?: \(first (?P<n>\d+) of \d+\))?: (?P<iqm>\S+) \[(?P<lo>\S+), (?P<hi>\S+)\]; "
    r"ISE / thesis LQR 1: (?P<c1>\S+), 2: (?P<c2>\S+), 3: (?P<c3>\S+), random: (?P<cr>\S+)$"
)


def policy_ise(policy, make: Callable[[], gym.Env], seeds: Sequence[int]) -> np.ndarray:
    """ISE [m^2 s] of ``policy`` (SB3 ``predict``) on one episode per seed of the env
    ``make()`` gives (:func:`baselines.evaluation.rollout.rollout`, deterministic)."""
    env = make()
    try:
        episodes = [rollout(policy, env, seed=s) for s in seeds]
    finally:
        env.close()
    return np.array([metrics_row("random", "policy", ep).ise for ep in episodes])


def score(
    policy,
    env_id: str = acld_gym.ENV_ID,
    wrappers: Sequence[Callable[[gym.Env], gym.Env]] = (),
    vec_normalize=None,
    episodes: int | None = None,
    quiet: bool = True,
    env_kwargs: dict | None = None,
) -> PolicyScore:
    """Score ``policy`` on the level ``env_id`` (module docstring).

    Parameters
    ----------
    policy : BaseAlgorithm, TrainedAgent, object or callable
        The policy (an SB3 model, a :class:`train.agent.TrainedAgent`, any object with SB3's
        ``predict``, or a callable ``observation -> action``), on the observation the
        ``wrappers`` give; its deterministic action.
        A :class:`train.agent.TrainedAgent` acts on the raw observation in volts (no
        wrappers), and is refused on a level whose observation differs from the one it was
        trained on (its fingerprint).
    env_id : str
        One of this package's ids (``ACLDBeam-v1``, ``ACLDBeamLab-v1``, ...).
    wrappers : sequence of callable
        The single-env wrappers it was trained with (each ``env -> env``), innermost first:
        classes (``UnitAction``) or callables (``functools.partial(ObserveModes, modes=1)``,
        ``lambda e: RescaleAction(e, -1.0, 1.0)``).
    vec_normalize : VecNormalize, path, False or None
        SB3's ``VecNormalize`` the policy was trained under (its observation statistics
        are applied; it is not changed), or the path of its saved ``vecnormalize.pkl``
        (unpickled: only from a source you trust); ``False``: none (a policy trained
        without one). None (default): the SB3 model's own env's if that is a
        ``VecNormalize``, else none; an SB3 model without an env (``PPO.load(path)``) is
        refused, since whether it was trained under a ``VecNormalize`` is unknown: pass its
        file or ``False``. For other policies None is ``False``.
    episodes : int or None
        Score on the first ``episodes`` of the test set and of the held-out random loads
        (at most their 20): a reduced run, quick, not the published score. None: all.
    quiet : bool
        No progress line while the references are computed (once per test set, cached).
    env_kwargs : dict or None
        The observation options the policy was trained with, for its episodes only:
        ``{"observe_commands": True}`` (the commands in flight appended, on a rig with a
        delay). The plant, the loads and the reward are the level's, and so are the
        references'; any other key is refused.

    Returns
    -------
    PolicyScore
        ``.iqm``, ``.ci``, ``.n_episodes``, ``.test_set``, ``.version``, ``.ise_rel_lqr``
        (cases 1, 2, 3, ``"random"``), ``.score`` (per-episode values), ``as_dict()``.

    Raises
    ------
    TypeError, ValueError
        One line naming the argument: a policy without ``predict`` that is not callable, an
        unknown ``env_id``, ``wrappers`` that do not fit the env or the policy, a
        ``vec_normalize`` of another observation or missing for a loaded SB3 model,
        ``episodes`` out of range.
    """
    env_id = check_env_id(env_id, "env_id")
    test = evaluation_set(env_id)
    if episodes is not None:
        test = test.first(check_int("episodes", episodes, 1, len(test.seeds)))
    wrappers = _check_wrappers(wrappers)
    kw = _check_env_kwargs(env_kwargs)
    probe = wrap(make_env(test, kw), wrappers, env_id)
    try:
        pol = as_policy(policy, vec_normalize, probe, wrappers)
        try:
            check_compatible(pol, probe)
        except ValueError as exc:
            raise ValueError(f"policy: {exc}") from None
        check_fits(pol, probe, env_id)
    finally:
        probe.close()

    refs = references(test, quiet=quiet)
    ise = policy_ise(pol, lambda: wrap(make_env(test, kw), wrappers, env_id), test.seeds)
    n_random = len(HELDOUT_SEEDS) if episodes is None else min(len(HELDOUT_SEEDS), len(test.seeds))
    cases = eval_episodes(n_random)
    case_ise = {
        case: float(
            np.mean(
                policy_ise(
                    pol,
                    lambda case=case: wrap(
                        gym.make(env_id, load_case=case, **kw), wrappers, env_id
                    ),
                    seeds,
                )
            )
        )
        for case, seeds in cases.items()
    }
    return PolicyScore(score_of(ise, refs), case_ise, lqr_ise(env_id, cases), env_id)


#: The env options :func:`score` passes to the policy's episodes: they change what it
#: observes, not what is scored.
OBSERVATION_OPTIONS = ("observe_commands",)


def _check_env_kwargs(env_kwargs) -> dict:
    """``env_kwargs`` as a dict of :data:`OBSERVATION_OPTIONS`; one line naming it else."""
    if env_kwargs is None:
        return {}
    if not isinstance(env_kwargs, dict):
        raise TypeError(f"env_kwargs: expected a dict or None, got {shown(env_kwargs)}")
    other = sorted(set(map(str, env_kwargs)) - set(OBSERVATION_OPTIONS))
    if other:
        raise ValueError(
            f"env_kwargs: only the observation options {list(OBSERVATION_OPTIONS)} (the "
            f"level's plant, loads and reward are what is scored), got {other}"
        )
    return dict(env_kwargs)


def _check_wrappers(wrappers) -> tuple:
    """``wrappers`` as a tuple of callables (``TypeError`` naming the first that is not)."""
    if wrappers is None:
        return ()
    if isinstance(wrappers, (str, bytes, Path)) or not isinstance(wrappers, Sequence):
        raise TypeError(
            f"wrappers must be a list of callables env -> wrapped env, got {shown(wrappers)}"
        )
    for i, w in enumerate(wrappers):
        if not callable(w):
            raise TypeError(
                f"wrappers[{i}] must be a wrapper class or a callable env -> wrapped env, "
                f"got {shown(w)}"
            )
    return tuple(wrappers)
