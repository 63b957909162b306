"""The agent's action in [-1, 1] to the piezo voltage, in numpy only: shared by training
(:class:`train.vec.VecAgentEnv`) and the trained agent (:class:`train.agent.TrainedAgent`),
which a core install (no torch, no stable-baselines3) loads and runs."""

from __future__ import annotations

import numpy as np

from acld_gym.physics.actuator import V_LIMIT

__all__ = ["VoltageMap"]


class VoltageMap:
    r"""Agent action :math:`a \in [-1, 1]` to piezo voltage [V].

    Plain: :math:`V = 120\,\mathrm{clip}(k a, -1, 1)` with the ``headroom`` k >= 1 (default
    1; :class:`acld_gym.wrappers.UnitAction`: the limit at :math:`a = \pm 1/k`, where a
    tanh-squashed policy can reach it). Residual on LQR:
    :math:`V = 120\,\mathrm{clip}(u_\mathrm{LQR}/120 + 2 k a, -1, 1)` with
    :math:`u_\mathrm{LQR}` the discrete LQR voltage of
    :class:`baselines.policies.LQRPolicy` for the same ``"estimate"`` observation
    (the unsaturated LQR voltage: the residual moves it by at most 240 V, so it
    refines LQR where LQR is unsure and cannot overrule it where LQR is far in
    saturation -- with the LQR voltage clipped first, training was unstable).
    The same map serves training (:class:`train.vec.VecAgentEnv`) and the trained
    agent (:class:`train.agent.TrainedAgent`).
    """

    def __init__(self, residual: str | None = None, mesh: str = "converged", headroom: float = 1.0):
        from acld_gym.wrappers import check_headroom

        if residual not in (None, "lqr"):
            raise ValueError(f"residual must be None or 'lqr', got {residual!r}")
        self.residual = residual
        self.headroom = check_headroom(headroom)
        self._lqr = None
        if residual == "lqr":
            from baselines.policies import LQRPolicy

            self._lqr = LQRPolicy(mesh=mesh)

    def __call__(self, action: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """Volts, shape (n, 1), for actions (n, 1) and raw observations (n, d)."""
        a = self.headroom * np.clip(np.asarray(action, dtype=np.float64).reshape(-1, 1), -1.0, 1.0)
        if self._lqr is not None:
            u0 = self._lqr.voltage(self._lqr.reduced_state(np.atleast_2d(obs)))[:, None]
            a = u0 / V_LIMIT + 2.0 * a
        a = np.clip(a, -1.0, 1.0)
        return (V_LIMIT * a).astype(np.float32)
