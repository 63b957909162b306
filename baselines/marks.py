"""Every level's references and what each one is: the three marks.

On every level (``ACLDBeam-v1``, ``ACLDBeamLab-v1``, ``ACLDBeamHard-v1``, ...) the
tables of :mod:`baselines.evaluate` and :mod:`baselines.analyze` show

* the thesis's designs, delay-free: the LQR and the SMC of the thesis (and the nominal
  MPC), designed on the nominal model without the rig's actuator
  (:mod:`baselines.policies`): under one period of delay they limit-cycle;
* the engineer's designs for the level's known actuator and sensor
  (:func:`baselines.engineer.engineer_policies`: what the level's datasheet says, not the
  episode's temperature or parameters);
* the plant oracle, the causal ceiling mark: the MPC on the episode's own plant and
  actuator, from the measurement, not knowing the load
  (:class:`baselines.oracle.PlantOracleMPC`);
* the clairvoyant bound, which knows the whole load (score v2's 1), and the passive beam
  (its 0).
"""

from __future__ import annotations

from .engineer import RigPolicy, engineer_policies
from .oracle import PlantOracleMPC
from .policies import mpc_available, policies_for

__all__ = ["KINDS", "ENGINEER", "level_references", "marks_for", "mark_labels"]

#: What each reference is, by name (the "what it is" column of the tables).
KINDS = {
    "passive": "passive beam (0)",
    "lqr": "thesis, delay-free",
    "smc": "thesis, delay-free",
    "mpc": "nominal MPC, delay-free",
    "mpc_reward": "reward MPC, delay-free",
    "mpc_oracle": "plant oracle",
    "bound": "clairvoyant (1)",
}
#: The kind of every policy of :func:`baselines.engineer.engineer_policies`.
ENGINEER = "engineer's design"


def level_references(env) -> dict:
    """Name -> policy (SB3 ``predict``) for ``env``'s level: passive, the thesis's LQR and
    SMC and the nominal MPC (:func:`baselines.policies.policies_for`), the engineer's
    designs (:func:`baselines.engineer.engineer_policies`) and, where the QP solver osqp is
    installed, the plant oracle ``mpc_oracle``. The bound is not a policy: the tables add
    it."""
    return {**policies_for(env), **marks_for(env)}


def marks_for(env) -> dict:
    """The engineer's designs of ``env``'s level and, where osqp is installed, the plant
    oracle ``mpc_oracle``: the marks :func:`level_references` adds to the thesis's."""
    out = engineer_policies(env)
    if mpc_available():
        out[PlantOracleMPC.name] = PlantOracleMPC()
    return out


def mark_labels(policies: dict) -> dict:
    """Name -> what it is, for ``policies`` (name -> policy): :data:`KINDS` by name, the
    engineer's designs (:class:`baselines.engineer.RigPolicy`) as :data:`ENGINEER`, the
    bound too; anything else (a trained agent) left out."""
    out = {}
    for name in [*policies, "bound"]:
        if isinstance(policies.get(name), RigPolicy):
            out[name] = ENGINEER
        elif name in KINDS:
            out[name] = KINDS[name]
    return out
