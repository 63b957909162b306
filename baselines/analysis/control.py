r"""A policy in control terms: :func:`analyze` runs every test of the package on one policy.

For any object with SB3's ``predict`` (volts), through the env ``env_id``:

* **closed-loop modes 1-3** (frequency, damping ratio) from a small tip pulse
  (:mod:`~baselines.analysis.modal`), and the passive beam's for reference;
* **peak reduction** of each mode's load-to-tip compliance peak against the passive beam
  (:mod:`~baselines.analysis.compliance`);
* for a policy that is linear about rest (:func:`~baselines.analysis.linear.small_signal_law`)
  the **exact closed-loop modes** of the sampled loop (truth plant, the env's observer, the
  gain), a check of the identified ones, and the **gain and phase margins** of the loop
  broken at the actuator (:mod:`~baselines.analysis.linear`);
* **effort** on the thesis cases 1-3 (:mod:`~baselines.analysis.effort`);
* the **score** on the env's test set (:mod:`baselines.evaluation.score`).

:meth:`Analysis.as_dict` is the JSON of ``python -m baselines.analyze``.
"""

from __future__ import annotations

from dataclasses import dataclass

import gymnasium as gym
import numpy as np

import acld_gym
from acld_gym.envs.presets import preset
from acld_gym.physics.actuator import patch_capacitance
from acld_gym.util.blas import one_blas_thread
from acld_gym.util.progress import Progress
from baselines.evaluation.references import References, references
from baselines.evaluation.rollout import metrics_row, rollout
from baselines.evaluation.score import Score, policy_ises, score_of
from baselines.evaluation.seeds import BASIS_SEEDS, evaluation_set

from .compliance import ComplianceTest, compliance_test
from .effort import Effort, effort, settled_from
from .excitation import PulseSuperposition
from .frequency import RESOLUTION, multisine
from .linear import LinearLaw, ObserverLoop, margins, small_signal_law
from .modal import RECORD_STEPS, ModalTest, modal_test, passive_modes
from .modes import Mode

__all__ = ["Analysis", "analyze", "CASES", "BASIS_SEEDS"]

#: The thesis cases of the effort measures.
CASES = (1, 2, 3)


@dataclass(frozen=True)
class Analysis:
    """Everything :func:`analyze` measured (module docstring)."""

    policy: str
    env_id: str
    open_loop_modes: list[Mode | None]
    edges: np.ndarray
    modal: ModalTest
    compliance: ComplianceTest
    law: LinearLaw | None
    law_reason: str
    exact_modes: list[Mode | None] | None
    margins: dict | None
    exact_compliance: np.ndarray | None
    cases: dict
    score: Score | None

    def as_dict(self) -> dict:
        """The JSON form: ``"closed_loop_modes"`` ordered by frequency (null values where
        the modal test found none), ``"peak_reduction_db"`` per mode, ``"score"``, ..."""

        def modes(ms):
            return (
                None
                if ms is None
                else [
                    m.as_dict()
                    if m is not None
                    else {"frequency_rad_s": None, "damping_ratio": None}
                    for m in ms
                ]
            )

        comp = self.compliance
        return {
            "policy": self.policy,
            "env_id": self.env_id,
            "closed_loop_modes": modes(self.modal.modes),
            "open_loop_modes": modes(self.open_loop_modes),
            "peak_reduction_db": comp.peak_reduction_db
            if comp.valid
            else [None] * len(self.open_loop_modes),
            "linear": self.law is not None,
            "small_signal_law": self.law_reason,
            "exact_closed_loop_modes": modes(self.exact_modes),
            "margins": self.margins,
            "identification": self.modal.as_dict(),
            "compliance": comp.as_dict(),
            "effort": {str(case): rec for case, rec in self.cases.items()},
            "score": None if self.score is None else self.score.as_dict(),
            "band_edges_rad_s": [float(e) for e in self.edges],
        }


def _case_record(policy, env_id: str, case, env_kwargs: dict, capacitance: float) -> dict:
    env = gym.make(env_id, load_case=case, **env_kwargs)
    ep = rollout(policy, env, seed=0)
    row = metrics_row(case, "policy", ep)
    e: Effort = effort(
        ep.voltage,
        ep.y,
        float(env.unwrapped.dt),
        settled_from(case),
        float(env.unwrapped.v_max),
        capacitance,
    )
    return {
        "ise": row.ise,
        "peak_mm": row.peak_mm,
        "settling_s": row.settling_s,
        "max_voltage_V": row.max_voltage_V,
        **e.as_dict(),
    }


def analyze(
    policy,
    env_id: str = acld_gym.ENV_ID,
    name: str | None = None,
    env_kwargs: dict | None = None,
    score_episodes: int | None = None,
    refs: References | None = None,
    basis_seeds: int = BASIS_SEEDS,
    resolution: float = RESOLUTION,
    quiet: bool = True,
) -> Analysis:
    """Every test of the module docstring on ``policy``.

    Parameters
    ----------
    policy
        Any object with SB3's ``predict`` returning volts.
    env_id : str
        The env (its arguments: ``env_kwargs``).
    name : str, optional
        The policy's name in the record (default: its ``name`` attribute).
    score_episodes : int, optional
        Score on the first n episodes of the test set only (a reduced run); 0: no score;
        None: the whole set.
    refs : References, optional
        The score's references, if already computed.
    basis_seeds : int
        Passive episodes averaged into the excitation's unit-pulse response (1 where each
        episode draws its plant: ``param_noise`` or ``temperature_range``).
    resolution : float
        Line spacing of the compliance test's multisine [rad/s]; its run is two periods
        of 2 pi / resolution seconds.
    quiet : bool
        No progress line.

    Notes
    -----
    Everything runs on one BLAS thread (:mod:`acld_gym.util.blas`).
    """
    kwargs = dict(env_kwargs or {})
    name = name or getattr(policy, "name", type(policy).__name__)
    if preset(env_id, **kwargs).randomized:  # each seed draws its own plant
        basis_seeds = 1
    test = None if score_episodes == 0 else evaluation_set(env_id)  # (an id without a
    if test is not None and score_episodes:  # test set: no score)
        test = test.first(score_episodes)
    n_score = 0 if test is None else len(test.seeds)
    with (
        one_blas_thread(),
        Progress(4 + (n_score + 1 if n_score else 0), f"analyze {name}", quiet) as progress,
    ):
        progress.stage("modal test")
        rig = PulseSuperposition(env_id, RECORD_STEPS, basis_seeds=basis_seeds, **kwargs)
        env = rig.env.unwrapped
        v_max, obs_size = float(env.v_max), int(env.observation_space.shape[0])
        open_modes, edges, _ = passive_modes(rig)
        modal = modal_test(policy, rig, edges, v_max)

        progress.stage("compliance test")
        ms = multisine(rig.dt, resolution)
        frig = PulseSuperposition(
            env_id, 2 * ms.n_period, basis_seeds=basis_seeds if modal.rests else 1, **kwargs
        )  # (no run without a rest)
        decay = [-np.log(abs(m.pole)) / rig.dt for m in modal.modes if m is not None]
        comp = compliance_test(
            policy, frig, ms, edges, v_max, modal.rest_voltage_V if modal.rests else None, decay
        )

        progress.stage("small-signal law")
        if hasattr(policy, "start_episode"):  # an oracle (evaluation.rollout): no static law
            law, why = None, "an oracle: it reads the episode's plant at reset, a dynamic law"
        else:
            law, why = small_signal_law(policy, obs_size, v_max)
        exact = marg = exact_h = None
        if law is not None:
            try:
                loop = ObserverLoop.from_env(rig.env)
            except ValueError as exc:
                why = f"{why}; no exact loop: {exc}"
            else:
                exact = loop.modes(law, edges, RECORD_STEPS)
                marg = margins(loop, law) if np.any(law.gain) else None  # no loop to break
                exact_h = loop.compliance(law, comp.omega)

        progress.stage("effort on the thesis cases")
        cap = patch_capacitance(env.nom.truth.params)
        cases = {c: _case_record(policy, env_id, c, kwargs, cap) for c in CASES}

        score = None
        if n_score:
            progress.stage(f"references of {test.name}")
            if refs is None:
                refs = references(test, kwargs)
            elif refs.seeds != test.seeds:
                raise ValueError(
                    f"refs: references of other episodes than {test.name}'s first {n_score}"
                )
            score = score_of(policy_ises(policy, test, kwargs, progress), refs)
    return Analysis(
        policy=name,
        env_id=env_id,
        open_loop_modes=open_modes,
        edges=edges,
        modal=modal,
        compliance=comp,
        law=law,
        law_reason=why,
        exact_modes=exact,
        margins=marg,
        exact_compliance=exact_h,
        cases=cases,
        score=score,
    )
