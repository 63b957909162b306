r"""The small-signal closed loop of an engineer's reference on a plant: its spectral radius.

A reference is a dynamic output feedback (:meth:`baselines.engineer.base.RigPolicy.
controller`: :math:`\xi_{k+1} = A_c \xi_k + b_c y_k`, :math:`u_k = c_c \xi_k + d_c y_k`,
ξ its filter's prior and the commands in flight). On a sampled plant :math:`(A_d, b)` with
the tip row c (the env's truth plant of an episode, with the amplifier's lag where the level
has one, :attr:`acld_gym.envs.beam_env.ACLDBeamEnv.episode_plant`) and a delay of d periods
the voltage that reaches the plant is the oldest command in flight, which is the
controller's own state (the same commands), so one period is

.. math::

    \begin{bmatrix} x \\ \xi \end{bmatrix}^+ =
    \begin{bmatrix} A_d + b\,d_c c\,[d = 0] & b\,e_s^T [d > 0] + b\,c_c [d = 0] \\
                    b_c c & A_c \end{bmatrix}
    \begin{bmatrix} x \\ \xi \end{bmatrix},

:math:`e_s` picking the oldest command in flight. As
:mod:`baselines.analysis.linear` does for the static references, stability is a spectral
radius below 1 of this one-period map (no limit active; the slew limit not binding).
"""

from __future__ import annotations

import numpy as np

from acld_gym.design.discrete import SampledSystem

from .. import arguments

__all__ = ["closed_loop", "spectral_radius", "env_plant"]


def env_plant(env) -> tuple[SampledSystem, np.ndarray]:
    """The current episode's sampled plant of ``env`` (any wrapper) and its tip row (the
    lag's state, if any, does not reach the tip)."""
    e = arguments.acld_env(env, ids=False)  # an env in an episode
    plant = e.episode_plant
    c = np.zeros(plant.Ad.shape[0])
    c[: e.nom.output.size] = e.nom.output
    return plant, c


def closed_loop(policy, plant: SampledSystem, c: np.ndarray) -> np.ndarray:
    """The loop's one-period map (module docstring) of ``policy`` (a
    :class:`~baselines.engineer.base.RigPolicy`) on ``plant`` with tip row ``c``."""
    Ac, bc, cc, dc = policy.controller()
    m = policy.model
    N, n, d = plant.Ad.shape[0], Ac.shape[0], m.delay
    b = plant.Bd[:, 0]
    A = np.zeros((N + n, N + n))
    A[:N, :N] = plant.Ad
    if d:
        A[:N, N + m.n_plant] = b
    else:
        A[:N, :N] += dc * np.outer(b, c)
        A[:N, N:] = np.outer(b, cc)
    A[N:, :N] = np.outer(bc, c)
    A[N:, N:] = Ac
    return A


def spectral_radius(policy, plant: SampledSystem, c: np.ndarray) -> float:
    """The largest eigenvalue magnitude of :func:`closed_loop` (stable below 1)."""
    return float(np.max(np.abs(np.linalg.eigvals(closed_loop(policy, plant, c)))))
