r"""The clairvoyant bound: the best any policy could do, knowing the whole load.

For an episode of N steps on the (nominal, noise-free) sampled plant, the tip
deflections are affine in the voltages, :math:`y = y_{free} + G V` with
:math:`G_{kj} = C_y A_d^{k-1-j} B_d` (k > j). The bound solves

.. math::

    \min_{|V_j| \le 120} \|y_{free} + G V\|_2^2

(a box-constrained least-squares problem, ``scipy.optimize.lsq_linear``).
No causal policy, which must act without knowing the future load, can have
a smaller ISE on the same episode.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from acld_gym.discrete import SampledSystem
from acld_gym.loads import TipLoad
from acld_gym.thesis import V_LIMIT

__all__ = ["BoundSolution", "clairvoyant_bound"]


@dataclass(frozen=True)
class BoundSolution:
    """Optimal voltages [V] (N,) and resulting tip deflections [m] (N,) at t = dt..N dt."""

    voltage: np.ndarray
    y: np.ndarray
    dt: float

    @property
    def ise(self) -> float:
        return float(np.sum(self.y**2) * self.dt)


def clairvoyant_bound(plant: SampledSystem, tip_index: int, load: TipLoad,
                      n_steps: int) -> BoundSolution:
    """Solve the bound for ``load`` over ``n_steps`` periods of ``plant``."""
    if not isinstance(n_steps, (int, np.integer)) or n_steps < 1:
        raise ValueError(f"n_steps must be a positive integer, got {n_steps!r}")
    n = plant.Ad.shape[0]
    x = np.zeros(n)
    y_free = np.empty(n_steps)
    h = np.empty(n_steps)  # voltage impulse response C A^m B
    xb = plant.Bd[:, 0].copy()
    for k in range(n_steps):
        f0, f1 = plant.load_samples(load, k * plant.dt)
        x = plant.Ad @ x + plant.load_increment(f0, f1)
        y_free[k] = x[tip_index]
        h[k] = xb[tip_index]
        xb = plant.Ad @ xb
    G = np.zeros((n_steps, n_steps))
    for k in range(n_steps):
        G[k, : k + 1] = h[k::-1]
    # Scale to mm and units of 120 V for a well-conditioned solve.
    res = lsq_linear(G * (V_LIMIT / 1e-3), -y_free / 1e-3, bounds=(-1.0, 1.0),
                     method="bvls", tol=1e-12, max_iter=10 * n_steps)
    v = V_LIMIT * res.x
    return BoundSolution(voltage=v, y=y_free + G @ v, dt=plant.dt)
