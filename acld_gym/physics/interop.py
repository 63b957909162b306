"""python-control views of the models: ``control.StateSpace`` with named, unit-tagged
signals, so that ``control.bode_plot``, ``control.step_response``, ``control.norm``,
``control.dcgain`` and the rest of the control engineer's toolbox work on them.

Inputs are ``"V[V]"`` (piezo voltage) and ``"f[N]"`` (tip load); the output is
``"y[m]"`` (tip deflection). Obtain them with
:meth:`acld_gym.physics.model.BeamModel.to_statespace`,
:meth:`acld_gym.physics.plant.Plant.to_statespace` and
:meth:`acld_gym.design.reduction.ReducedModel.to_statespace`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["statespace", "INPUTS", "OUTPUTS"]

INPUTS = ("V[V]", "f[N]")
OUTPUTS = ("y[m]",)


def statespace(
    A: np.ndarray,
    B: np.ndarray,
    E: np.ndarray | None,
    C: np.ndarray,
    name: str,
    states: list[str] | None = None,
):
    """``control.ss`` of ``x' = A x + B V + E f``, ``y = C x`` (without E: voltage only)."""
    import control  # python-control takes ~2.7 s to import: only a conversion needs it

    Bm = np.hstack([B, E]) if E is not None and E.size else B
    inputs = list(INPUTS[: Bm.shape[1]])
    n = A.shape[0]
    return control.ss(
        A,
        Bm,
        C,
        np.zeros((C.shape[0], Bm.shape[1])),
        name=name,
        inputs=inputs,
        outputs=list(OUTPUTS),
        states=states or [f"x{i}" for i in range(n)],
    )
