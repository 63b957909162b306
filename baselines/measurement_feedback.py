"""A reference policy for the ``"measurement"`` observation (:class:`MeasurementFeedback`):
it runs the env's nominal observer itself and feeds the policy the estimate. Public face:
:mod:`baselines.policies`.
"""

from __future__ import annotations

import numpy as np

from acld_gym.envs.step import OBS_HIST, Y_SCALE, estimate_map
from acld_gym.physics.actuator import V_LIMIT

__all__ = ["MeasurementFeedback"]


class MeasurementFeedback:
    r"""A reference policy for the ``"measurement"`` observation (the last 8 tip
    measurements and the last command): it runs the nominal observer itself -- the same
    sampled filter the env runs for its ``"estimate"`` observation,

    .. math::

        \hat x_k = (A - L_p C)\,\hat x_{k-1} + L_p y_{k-1} + B u_{k-1}, \qquad
        e_k = [\hat x_k, y_k]\,M,

    from rest at the episode's start -- and gives ``policy`` the estimate as the
    ``"estimate"`` observation would. It keeps its filter in SB3's ``state``
    (``predict(obs, state, episode_start)``; a None state or ``episode_start`` starts an
    episode), so it acts on what it observes: measurements rounded to float32 as the
    observation carries them. ``policy`` is a reference policy on the estimate
    (:class:`baselines.policy_base._Policy`), ``observer`` the env's nominal observer.
    """

    def __init__(self, policy, observer):
        if observer.fed_load:
            raise ValueError(
                "MeasurementFeedback needs an observer that is not fed the load "
                "(observer='kalman'): the measurement observation has no load"
            )
        self.policy = policy
        self.name = policy.name
        self.observer = observer
        self._est = estimate_map(observer, policy.nom.xr_scale)

    @property
    def observation_fingerprint(self) -> dict:
        return self.policy.observation_fingerprint

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol with state: ``(actions, state)``, state = the filter ``[xhat, y]``."""
        obs = np.asarray(observation, dtype=np.float64)
        batched = obs.ndim == 2
        o = np.atleast_2d(obs)
        if o.shape[-1] != OBS_HIST + 1:
            raise ValueError(
                f"obs: MeasurementFeedback needs the env's 'measurement' "
                f"observation ({OBS_HIST + 1} values), got shape {obs.shape}"
            )
        ob, k = self.observer, self.observer.n
        y, u_prev = o[:, OBS_HIST - 1] * Y_SCALE, o[:, OBS_HIST] * V_LIMIT
        xhat = np.zeros((o.shape[0], k))
        if state is not None:
            old = np.atleast_2d(np.asarray(state, dtype=np.float64))
            lp = ob.Lp[:, 0]
            xhat = (
                old[:, :k] @ (ob.A - np.outer(lp, ob.C[0])).T
                + np.outer(old[:, k], lp)
                + np.outer(u_prev, ob.B[:, 0])
            )
            if episode_start is not None:
                xhat[np.atleast_1d(np.asarray(episode_start, dtype=bool))] = 0.0
        estimate = np.hstack([xhat, y[:, None]]) @ self._est
        e = np.hstack([estimate, y[:, None] / Y_SCALE]).astype(np.float32)
        action, _ = self.policy.predict(e if batched else e[0], deterministic=deterministic)
        return action, np.hstack([xhat, y[:, None]])
