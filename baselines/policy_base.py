"""The reference policies' common ``predict`` plumbing (:class:`_Policy`): the nominal
design they are built on, the reduced-state estimate decoded from the ``"estimate"``
observation, clipping to the voltage limit, and ``for_env``. The policies themselves:
:mod:`baselines.policies` (their public face) and :mod:`baselines.mpc_policy`.
"""

from __future__ import annotations

import numpy as np

from acld_gym.design.feedback import Feedback
from acld_gym.design.nominal import NominalDesign
from acld_gym.envs.fingerprint import design_fingerprint
from acld_gym.physics.actuator import V_LIMIT

from . import arguments
from .measurement_feedback import MeasurementFeedback

__all__: list[str] = []


class _Policy:
    """Common ``predict`` plumbing: batch handling, estimate decoding, clipping. Built on
    ``nom``, else on the nominal design of ``dt`` [s] (default 1 ms) and ``mesh`` (default
    ``"converged"``); :func:`baselines.arguments.nominal` checks them (a conflict refused)."""

    name = "policy"

    def __init__(self, dt: float | None = None, nom=None, mesh: str | None = None):
        self.nom = self._nominal(dt, nom, mesh)
        self.k = self.nom.design.reduced.order

    def _nominal(self, dt, nom, mesh) -> NominalDesign:
        return arguments.nominal(type(self).__name__, dt, nom, mesh)

    @classmethod
    def for_env(cls, env, **kwargs):
        """The policy designed on ``env``'s nominal model (any Gymnasium wrapper); for an env
        observed through ``obs_mode="measurement"`` wrapped in :class:`MeasurementFeedback`
        (it runs the env's nominal observer itself)."""
        e = arguments.acld_env(env)
        policy = cls(nom=e.nom, **kwargs)
        if e.obs_mode == "measurement":
            return MeasurementFeedback(policy, e.nom.observer(e.observer_kind))
        return policy

    @property
    def observation_fingerprint(self) -> dict:
        """The design the policy decodes the observation with
        (:func:`acld_gym.envs.fingerprint.design_fingerprint`)."""
        return design_fingerprint(self.nom)

    def reduced_state(self, obs: np.ndarray) -> np.ndarray:
        obs = np.asarray(obs, dtype=np.float64)
        if obs.shape[-1] != self.k + 1:
            raise ValueError(
                f"obs: {type(self).__name__} needs the env's 'estimate' observation "
                f"({self.k + 1} values), got shape {obs.shape}"
            )
        return obs[..., : self.k] * self.nom.xr_scale

    #: The voltage law on the reduced state (:class:`acld_gym.design.feedback.Feedback`);
    #: set by the subclass (MPC has none: it solves a QP).
    law: Feedback

    def voltage(self, xr: np.ndarray) -> np.ndarray:
        """Requested voltage [V] for reduced states ``xr`` (n, k)."""
        return self.law.voltage(xr)

    def small_signal_gain(self) -> np.ndarray:
        """K with V = -K x_r where no limit or switching is active (the linearization
        about rest), for stability checks (:mod:`baselines.robustness`)."""
        return self.law.small_signal_gain()

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: returns ``(actions, state)``; actions in volts, shape (n, 1) or (1,)."""
        obs = np.asarray(observation)
        batched = obs.ndim == 2
        xr = self.reduced_state(np.atleast_2d(obs))
        v = np.clip(self.voltage(xr), -V_LIMIT, V_LIMIT).astype(np.float32)[:, None]
        return (v if batched else v[0]), state
