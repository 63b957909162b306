r"""The engineer's design model of a level: the sampled reduced plant, the amplifier's lag
where the level has one, and the commands in flight of its known delay.

What it is built from is what the level's datasheet states
(:class:`acld_gym.envs.config.EnvConfig`: ``actuator_delay``, ``amplifier_bandwidth``,
``slew_rate``, ``sensor_noise``, ``y_ref``, ``lam``) and the package's public nominal
design (:func:`acld_gym.design.nominal.nominal_design`: the reduced model of the nominal
beam at 20 °C). The episode's temperature and parameters are not in it.

**The plant part** :math:`x_p` is the reduced state :math:`x_r` (k states), and with an
amplifier of bandwidth :math:`f_a` also the patch voltage :math:`V_p`
(:func:`acld_gym.physics.actuator.with_amplifier`), sampled exactly at the control period
(zero-order hold, :func:`acld_gym.design.discrete.discretize`):

.. math:: x_{p,k+1} = A_p x_{p,k} + b_p\,v_k + e_p f_k, \qquad y_k = c_p x_{p,k},

with :math:`v_k` the voltage that reaches the amplifier in period k.

**The delay** of d periods (:math:`v_k = u_{k-d}`, u the command) is a shift register of
the commands in flight, oldest first, :math:`s_k = [u_{k-d}, \dots, u_{k-1}]`
(Åström & Wittenmark, *Computer-Controlled Systems*; MATLAB's ``absorbDelay``: d poles at
z = 0):

.. math::

    z_{k+1} = \begin{bmatrix} A_p & b_p e_1^T \\ 0 & J \end{bmatrix} z_k +
              \begin{bmatrix} 0 \\ e_d \end{bmatrix} u_k, \qquad
    z = \begin{bmatrix} x_p \\ s \end{bmatrix},

J the shift (ones on the superdiagonal). With d = 0 it is the plant part driven by u.

**The slew limit** :math:`|v_k - v_{k-1}| \le` ``slew_rate * dt`` is not linear: the
estimators apply it to the commands (they know them and the amplifier's last output, so the
voltage that reaches the amplifier is known exactly); the MPC has it as a rate
constraint. At the lab rig's 1 kHz it is 4180 V per period, beyond the 240 V range: it
never binds there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from acld_gym.design.discrete import SampledSystem, discretize
from acld_gym.design.nominal import NominalDesign
from acld_gym.physics.actuator import V_LIMIT, with_amplifier

from .. import arguments

__all__ = ["RigModel", "rig_model", "shift_system"]


@dataclass(frozen=True, eq=False)
class RigModel:
    """The design model of one level (module docstring).

    Attributes
    ----------
    plant : SampledSystem
        The plant part :math:`(A_p, b_p)` (the reduced model, with the lag's state last).
    c : ndarray (n_p,)
        The tip row :math:`c_p` [m per state unit].
    delay : int
        d, the commands in flight.
    slew_step : float or None
        The largest change of the amplifier's output per period [V] (None: unlimited).
    scale : ndarray (n_p,)
        Each plant state's magnitude in the passive response to thesis case 1 (the
        nominal design's ``xr_scale``; 120 V for the patch voltage): the scaling of every
        Riccati solve.
    sensor_std, y_ref, lam : float
        The sensor's noise [m] and the reward's deflection scale [m] and voltage weight.
    """

    plant: SampledSystem
    c: np.ndarray
    delay: int
    slew_step: float | None
    scale: np.ndarray
    sensor_std: float
    y_ref: float
    lam: float

    @property
    def n_plant(self) -> int:
        return self.plant.Ad.shape[0]

    @property
    def n(self) -> int:
        """States of the augmented model, :math:`n_p + d`."""
        return self.n_plant + self.delay

    def augmented(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, b)`` of the augmented model (module docstring), b a column (n, 1)."""
        return shift_system(self.plant.Ad, self.plant.Bd[:, 0], self.delay)

    def augmented_output(self) -> np.ndarray:
        """The tip row of the augmented state, ``[c_p, 0]``."""
        return np.concatenate([self.c, np.zeros(self.delay)])

    def augmented_scale(self) -> np.ndarray:
        """The state scaling of the augmented model (the commands in units of 120 V)."""
        return np.concatenate([self.scale, np.full(self.delay, V_LIMIT)])

    def reward_weights(self, deflection: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""``(Q, R, N)`` of the env's step cost on the augmented model,
        :math:`\ell = z^T Q z + 2 z^T N u + R u^2`.

        The env charges :math:`(y_{k+1} / y_{ref})^2 + \lambda (V_k / 120)^2` per step,
        :math:`y_{k+1}` the tip at the end of the period and :math:`V_k` the voltage the
        amplifier applies. With :math:`y_{k+1} = c\,(A z_k + b u_k)`:

        .. math::

            Q = \frac{A^T c^T c A}{y_{ref}^2}, \quad
            N = \frac{A^T c^T c\, b}{y_{ref}^2}, \quad
            R = \frac{b^T c^T c\, b}{y_{ref}^2} + \frac{\lambda}{120^2}.

        The voltage term is charged on the command :math:`u_k`: exact without delay and
        lag (:math:`V_k = u_k`); with a delay :math:`V_k = u_{k-d}`, so the sum over an
        infinite horizon is the same up to the first d terms, which no command changes;
        the lab's 60 kHz amplifier reaches its command within :math:`e^{-377}` of it by
        the period's end.
        ``deflection`` multiplies the deflection term (1: the env's reward).
        """
        A, b = self.augmented()
        c = self.augmented_output()
        ca, cb = c @ A, float(c @ b[:, 0])
        w = deflection / self.y_ref**2
        Q = w * np.outer(ca, ca)
        N = (w * cb * ca)[:, None]
        R = np.array([[w * cb**2 + self.lam / V_LIMIT**2]])
        return Q, R, N

    def drive(self, command: np.ndarray, held: np.ndarray) -> np.ndarray:
        """The voltage the amplifier applies for ``command`` after its last output
        ``held`` (the slew limit; ``command`` itself without one)."""
        if self.slew_step is None:
            return command
        return held + np.clip(command - held, -self.slew_step, self.slew_step)


def shift_system(Ap: np.ndarray, bp: np.ndarray, d: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A, b)`` of the plant ``(Ap, bp)`` driven through a delay of ``d`` periods, the
    commands in flight appended to its state, oldest first (module docstring)."""
    n = Ap.shape[0]
    A = np.zeros((n + d, n + d))
    b = np.zeros((n + d, 1))
    A[:n, :n] = Ap
    if d:
        A[:n, n] = bp
        A[n : n + d - 1, n + 1 : n + d] = np.eye(d - 1)
        b[n + d - 1, 0] = 1.0
    else:
        b[:n, 0] = bp
    return A, b


def rig_model(nom: NominalDesign, config) -> RigModel:
    """The design model of ``config`` (:class:`acld_gym.envs.config.EnvConfig`) on the
    nominal design ``nom``: what the level's datasheet states, nothing of an episode."""
    arguments.matching("rig_model", arguments.design(nom), arguments.env_config(config))
    r = nom.design.reduced
    if config.amplifier_bandwidth is None:
        plant, c, scale = nom.reduced, r.C[0], nom.xr_scale
    else:
        A, B, E = with_amplifier(r.A, r.B, r.E, config.amplifier_bandwidth)
        plant = discretize(A, B, E, nom.plant.dt, nom.plant.substeps)
        c = np.append(r.C[0], 0.0)
        scale = np.append(nom.xr_scale, V_LIMIT)
    return RigModel(
        plant=plant,
        c=np.asarray(c, dtype=float),
        delay=int(config.actuator_delay),
        slew_step=config.slew_step,
        scale=np.asarray(scale, dtype=float),
        sensor_std=max(float(config.sensor_noise), 1e-9),
        y_ref=float(config.y_ref),
        lam=float(config.lam),
    )
