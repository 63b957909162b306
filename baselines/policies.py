"""Reference policies for ``ACLDBeam-v1`` (and every registered id) with
stable-baselines3's ``predict`` protocol.

They are designed on the nominal reduced model sampled at the env's control
period (:func:`acld_gym.design.nominal.nominal_design`) and read the reduced-state estimate
from the ``"estimate"`` observation (``obs[:k] * xr_scale``, k the design order: 8 on the
converged plant, 6 on the thesis mesh), so
``evaluate_policy`` and :mod:`baselines.evaluate` treat them like agents.

A policy is designed for one plant (``mesh``) and one observation basis: build it
for an env with ``LQRPolicy.for_env(env)`` (or pass ``mesh=``); its
``observation_fingerprint`` must equal the env's.

The parts: the common plumbing in :mod:`baselines.policy_base`, the MPCs in
:mod:`baselines.mpc_policy`, the measurement-observation wrapper in
:mod:`baselines.measurement_feedback`; every name is importable from here. A level's
thesis references by name: :func:`policies_for` (an env's), :func:`default_policies` (a
mesh's).
"""

from __future__ import annotations

import numpy as np

from acld_gym.design.feedback import (
    THESIS_LQR_WEIGHT,
    THESIS_SMC_WEIGHT,
    Feedback,
    discrete_lqr_gain,
    passive,
)

from . import arguments
from .measurement_feedback import MeasurementFeedback
from .mpc_policy import MPC_MISSING, STATE_WEIGHT, MPCPolicy, RewardMPCPolicy, mpc_available
from .policy_base import _Policy

__all__ = [
    "PassivePolicy",
    "LQRPolicy",
    "SMCPolicy",
    "MPCPolicy",
    "RewardMPCPolicy",
    "MeasurementFeedback",
    "MPC_MISSING",
    "mpc_available",
    "discrete_lqr_gain",
    "STATE_WEIGHT",
    "policy_classes",
    "default_policies",
    "policies_for",
]


class PassivePolicy(_Policy):
    """V = 0: the passive (PCLD) beam."""

    name = "passive"

    def __init__(self, dt: float | None = None, nom=None, mesh: str | None = None):
        super().__init__(dt, nom, mesh)
        self.law = passive(self.k)


class LQRPolicy(_Policy):
    r"""Discrete LQR with the thesis's weights: :math:`Q = 10^{11} S_R^T S_R`, R = 1
    (eqs. 65-67), on the reduced model sampled at ``dt``."""

    name = "lqr"

    def __init__(
        self, dt: float | None = None, weight: float = THESIS_LQR_WEIGHT, nom=None, mesh=None
    ):
        weight = arguments.lqr_weight(weight)
        super().__init__(dt, nom, mesh)
        self.law = self.nom.lqr_law(weight)
        self.K = self.law.a[None]


class SMCPolicy(_Policy):
    r"""Discrete sliding-mode control with the thesis's weights (eqs. 68-72, sampled).

    * Surface :math:`\sigma = s x_r` with :math:`s = (1 + B_d^T X B_d)^{-1} B_d^T X`,
      X from the DARE with :math:`Q = 10^6 S_R^T S_R`, R = 1 (sigma in volts). The
      thesis's choice -- the LQR gain itself as the surface -- has unstable
      sliding dynamics once sampled (the discrete gain contains :math:`A_d`;
      its zero dynamics have |z| = 1.01), while :math:`B_d^T X` gives
      |z| = 0.975.
    * Equivalent control (deadbeat on sigma):
      :math:`u_{eq} = -(s B_d)^{-1} s A_d x_r`.
    * Switching term :math:`-\operatorname{sign}(s B_d)\,\eta\,
      \operatorname{sat}(\sigma/\varepsilon)` with
      :math:`\eta = 1.5 |s E_d / s B_d|` (the thesis's 1.5 margin over one
      period of 1 N load, ``MixedBeamModel.m``).
    * Boundary layer :math:`\varepsilon` = 1000 V (default). In discrete time
      the voltage limit bounds the change of sigma per step to about
      :math:`2 |s B_d| \cdot 120` V = 235 V; a layer thinner than that
      band makes the switching term a relay on sigma that never settles
      (with the thesis's eps = 1 the beam does not settle within 1 s).
    """

    name = "smc"

    def __init__(
        self,
        dt: float | None = None,
        weight: float = THESIS_SMC_WEIGHT,
        eta_factor: float = 1.5,
        eps: float = 1000.0,
        nom=None,
        mesh: str | None = None,
    ):
        weight, eps = arguments.positive("weight", weight), arguments.positive("eps", eps, "V")
        eta_factor = arguments.non_negative("eta_factor", eta_factor)
        super().__init__(dt, nom, mesh)
        sr = self.nom.reduced
        _, X = discrete_lqr_gain(sr.Ad, sr.Bd, self.nom.design.state_weight(weight), np.eye(1))
        B = sr.Bd[:, 0]
        self.s = (B @ X) / (1.0 + B @ X @ B)
        self.sb = float(self.s @ B)
        self.a = (self.s @ sr.Ad) / self.sb
        self.c = float(np.sign(self.sb)) * eta_factor * abs(float(self.s @ sr.Ed[:, 0]) / self.sb)
        self.eps = float(eps)
        # the law itself is the continuous design's form (acld_gym.design.feedback)
        self.law = Feedback(a=self.a, s=self.s, c=self.c, eps=self.eps, name="smc")


# --- the thesis's references of a level, by name ---------------------------------------
def policy_classes() -> tuple:
    """Passive, LQR, SMC and MPC; without MPC where its QP solver is not installed (a
    core install: :data:`MPC_MISSING`)."""
    return (PassivePolicy, LQRPolicy, SMCPolicy) + ((MPCPolicy,) if mpc_available() else ())


def default_policies(mesh: str = "converged", dt: float = 1e-3) -> dict:
    """Passive, LQR, SMC and MPC (:func:`policy_classes`) designed on the nominal ``mesh``
    plant."""
    return {cls.name: cls(dt=dt, mesh=mesh) for cls in policy_classes()}


def policies_for(env) -> dict:
    """Passive, LQR, SMC and MPC (:func:`policy_classes`) designed for ``env`` (its nominal
    model and observation)."""
    return {cls.name: cls.for_env(env) for cls in policy_classes()}
