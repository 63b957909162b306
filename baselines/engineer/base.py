r"""What every engineer's reference shares: its own Kalman filter on the tip measurement, fed
the voltage that actually reaches the amplifier, and the ``predict`` protocol.

**The observation.** The policy reads only the tip measurement :math:`y_k` from the env's
observation -- the last entry of the ``"estimate"`` observation (its tip, ``y / Y_SCALE``),
or the newest of the ``"measurement"`` observation's eight -- and keeps its own filter: the
env's built-in observer behind the ``"estimate"`` observation is driven by the command, not
by the delayed voltage, so a design for the rig's delay cannot use its estimate.

**The filter** (steady-state Kalman, :func:`baselines.engineer.riccati.kalman_gain`) runs
on the plant part of the design model (:class:`baselines.engineer.model.RigModel`); the
commands in flight are known exactly, and so is the voltage the amplifier applies (the
slew limit applied to them from its last output):

.. math::

    \hat x_{k|k} = \hat x_{k|k-1} + M (y_k - c_p \hat x_{k|k-1}), \qquad
    u_k = \operatorname{sat}_{120}\big(\kappa(\hat z_k)\big), \quad
    \hat z_k = [\hat x_{k|k}; u_{k-d}, \dots, u_{k-1}],

.. math::

    v_k = \operatorname{slew}(u_{k-d}), \qquad
    \hat x_{k+1|k} = A_p \hat x_{k|k} + b_p v_k ,

κ the policy's law (a gain, or the MPC's QP). The filter's state, the commands in flight
and the amplifier's last output are SB3's ``state`` (``predict(obs, state,
episode_start)``); a None state or ``episode_start`` starts an episode at rest, as the env
does.
"""

from __future__ import annotations

import numpy as np

from acld_gym.envs.fingerprint import design_fingerprint
from acld_gym.envs.step import OBS_HIST, Y_SCALE
from acld_gym.physics.actuator import V_LIMIT

from .. import arguments
from .designs import design_kwargs
from .model import RigModel, rig_model
from .riccati import kalman_gain

__all__ = ["RigPolicy", "measurement_index"]


def measurement_index(nom, obs_mode: str) -> int:
    """Where the newest tip measurement (``y / Y_SCALE``) sits in an observation of
    ``obs_mode``; ``ValueError`` for ``"full"`` (the privileged state, not a rig's)."""
    if obs_mode == "estimate":
        return nom.design.reduced.order
    if obs_mode == "measurement":
        return OBS_HIST - 1
    raise ValueError(
        f"obs_mode: an engineer's reference reads the tip measurement of the 'estimate' "
        f"or 'measurement' observation, got {obs_mode!r}"
    )


class RigPolicy:
    """An output-feedback policy on the level's design model (module docstring); a
    subclass sets the law :meth:`command` and its small-signal gain."""

    name = "rig"

    def __init__(
        self,
        nom,
        config,
        model_std: float | None = None,
        load_std: float = 1.0,
        model: RigModel | None = None,
    ):
        owner = type(self).__name__
        self.nom, self.config = arguments.design(nom), arguments.env_config(config)
        arguments.matching(owner, nom, config)
        if model is not None and not isinstance(model, RigModel):
            raise ValueError(f"model must be a RigModel or None, got {type(model).__name__}")
        model_std = arguments.model_std(model_std)
        self.load_std = arguments.positive("load_std", load_std, "N")
        #: The design model (:func:`~baselines.engineer.model.rig_model` of ``config``
        #: unless given: the designs are built on whatever coordinates it has).
        self.model: RigModel = rig_model(nom, config) if model is None else model
        self.obs_mode = config.obs_mode
        self._iy = measurement_index(nom, config.obs_mode)
        self.model_std = config.model_std if model_std is None else model_std
        m = self.model
        if np.ndim(self.model_std) and self.model_std.shape != (m.n_plant,):
            raise ValueError(
                f"model_std: expected one value or {m.n_plant} (one per state of the plant "
                f"part), got {self.model_std.size}"
            )
        self.M = kalman_gain(
            m.plant.Ad,
            m.c,
            m.plant.Ed[:, 0],
            m.sensor_std,
            m.scale,
            load_std=self.load_std,
            model_std=self.model_std,
        )

    @classmethod
    def for_env(cls, env, **kwargs):
        """The policy for ``env`` (any wrapper): its nominal design and configuration, with
        the level's design parameters (:data:`baselines.engineer.designs.DESIGNS`;
        ``kwargs`` replace them)."""
        e = arguments.acld_env(env)
        return cls(e.nom, e.config, **(design_kwargs(e.nom, e.config) | kwargs))

    @property
    def observation_fingerprint(self) -> dict:
        """The design and observation the policy was built for
        (:func:`acld_gym.envs.fingerprint.design_fingerprint` and the mode)."""
        return {**design_fingerprint(self.nom), "obs_mode": self.obs_mode}

    # --- the law ----------------------------------------------------------------------
    def command(self, z: np.ndarray, held: np.ndarray) -> np.ndarray:
        """The commands [V] (before the ±120 V clip) for augmented estimates ``z`` (N, n),
        the amplifier's last output ``held`` (N,) [V]."""
        raise NotImplementedError

    def small_signal_gain(self) -> np.ndarray:
        """K (n,) with :math:`u = -K \\hat z` where no limit is active."""
        raise NotImplementedError

    # --- the protocol -----------------------------------------------------------------
    @property
    def state_size(self) -> int:
        """Entries of the state per env: the filter's prior, the commands in flight, the
        amplifier's last output."""
        return self.model.n + 1

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol with state: ``(volts, state)``, volts (N, 1) or (1,) float32."""
        obs = np.asarray(observation, dtype=np.float64)
        batched = obs.ndim == 2
        o = np.atleast_2d(obs)
        if o.ndim != 2 or o.shape[-1] <= self._iy:
            raise ValueError(
                f"obs: {type(self).__name__} needs the env's {self.obs_mode!r} observation, "
                f"got shape {obs.shape}"
            )
        m, n_p, d = self.model, self.model.n_plant, self.model.delay
        y = o[:, self._iy] * Y_SCALE
        s = np.zeros((o.shape[0], self.state_size))
        if state is not None:
            s[:] = np.atleast_2d(np.asarray(state, dtype=np.float64))
            if episode_start is not None:
                s[np.atleast_1d(np.asarray(episode_start, dtype=bool))] = 0.0
        prior, flight, held = s[:, :n_p], s[:, n_p : n_p + d], s[:, -1]
        post = prior + np.outer(y - prior @ m.c, self.M)
        u = np.clip(self.command(np.hstack([post, flight]), held), -V_LIMIT, V_LIMIT)
        u = u.astype(np.float32)
        u64 = u.astype(np.float64)
        drive = m.drive(flight[:, 0] if d else u64, held)
        new = np.empty_like(s)
        new[:, :n_p] = post @ m.plant.Ad.T + np.outer(drive, m.plant.Bd[:, 0])
        if d:
            new[:, n_p : n_p + d - 1] = flight[:, 1:]
            new[:, n_p + d - 1] = u64
        new[:, -1] = drive
        return (u[:, None] if batched else u[:1]), new

    # --- the small-signal controller ----------------------------------------------------
    def controller(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        r"""The policy about rest as a discrete LTI system from the measurement to the
        command, ``(Ac, bc, cc, dc)``: :math:`\xi_{k+1} = A_c \xi_k + b_c y_k`,
        :math:`u_k = c_c \xi_k + d_c y_k`, :math:`\xi = [\hat x_{k|k-1}; s]` (no limit
        active; the slew limit not binding)."""
        m, n_p, d = self.model, self.model.n_plant, self.model.delay
        n = n_p + d
        K = np.asarray(self.small_signal_gain(), dtype=float).reshape(n)
        Kx, Ks = K[:n_p], K[n_p:]
        Ap, bp, c, M = m.plant.Ad, m.plant.Bd[:, 0], m.c, self.M
        F = np.eye(n_p) - np.outer(M, c)  # xhat_{k|k} = F xhat + M y
        cc = np.concatenate([-Kx @ F, -Ks])
        dc = -float(Kx @ M)
        Ac = np.zeros((n, n))
        bc = np.zeros(n)
        Ac[:n_p, :n_p] = Ap @ F
        bc[:n_p] = Ap @ M
        if d:
            Ac[:n_p, n_p] += bp  # driven by the oldest command in flight
            Ac[n_p : n - 1, n_p + 1 : n] = np.eye(d - 1)
            Ac[n - 1] = cc
            bc[n - 1] = dc
        else:
            Ac[:n_p] += np.outer(bp, cc)
            bc[:n_p] += bp * dc
        return Ac, bc, cc, dc
