"""The one reading of an OSQP result that every MPC of the package shares
(:class:`baselines.policies.MPCPolicy`, :class:`baselines.oracle.PlantOracleMPC`,
:class:`baselines.engineer.ActuatorMPCPolicy`)."""

from __future__ import annotations

import numpy as np

__all__ = ["ACCEPTED", "SETTINGS", "solution"]

#: The statuses whose solution is used (OSQP stops at its tolerance or its iteration limit
#: with "solved inaccurate": the first move is still the QP's to that accuracy).
ACCEPTED = ("solved", "solved inaccurate")


#: The OSQP settings every MPC of the package solves with (its accuracy: 1e-7, no polishing).
SETTINGS = {
    "verbose": False,
    "eps_abs": 1e-7,
    "eps_rel": 1e-7,
    "polishing": False,
    "max_iter": 20000,
}


def solution(res, who: str) -> np.ndarray:
    """The solution ``res.x`` of an OSQP ``solve(raise_error=False)`` whose status is
    accepted (:data:`ACCEPTED`). OSQP catches Ctrl-C itself and returns the status
    ``"interrupted"``: that is re-raised as ``KeyboardInterrupt``, so a command ends as on
    any Ctrl-C (:func:`acld_gym.util.validate.run_main`: one line, exit status 130); any
    other status is a ``RuntimeError`` naming ``who`` and the status."""
    status = res.info.status
    if status in ACCEPTED:
        return res.x
    if status == "interrupted":
        raise KeyboardInterrupt
    raise RuntimeError(f"{who}: OSQP returned status {status!r}")
