"""The thesis's design pipeline in one call: plant -> reduction -> observer -> controllers.

Everything downstream (the reproduction, the environment's reference
policies) starts from a :class:`Design`, so the pipeline is written once. The
design model (the reduced model -- 8 states on the converged plant, 6 on the thesis
mesh -- and everything designed on it) is kept
apart from the truth model it was reduced from (:class:`acld_gym.physics.plant.Plant`):
the environment simulates the truth, possibly with randomized parameters, while
observers and baselines keep the nominal design.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from acld_gym.design.feedback import Feedback, lqr, passive, projected_weight, smc
from acld_gym.design.observer import Observer, kalman_observer, thesis_observer
from acld_gym.design.reduction import ReducedModel, schur_balanced_truncation
from acld_gym.physics.model import BeamModel, resolve
from acld_gym.physics.plant import Plant, fe_plant

__all__ = ["Design", "design", "REDUCED_ORDER", "DESIGN_ORDER"]

#: Order of the reduced model (thesis sec. 3.3, Fig. 5).
REDUCED_ORDER = 6
#: Design-model order per truth plant. The thesis mesh keeps the thesis's 6 (modes 1-3;
#: sigma_6 / sigma_7 = 9.4). On the converged beam the fourth mode falls from 11932 to
#: 5330 rad/s, below twice the 1 kHz control's Nyquist frequency (it aliases to 953 rad/s,
#: next to mode 2): 6 states give sigma_6 / sigma_7 = 4.2 and LQR/SMC loops with the
#: observer that are unstable at small amplitude (spectral radius 1.011); 8 states (modes
#: 1-4) give sigma_8 / sigma_9 = 10.4 and stable loops (the mesh study,
#: docs/mesh.md).
DESIGN_ORDER = {"thesis": 6, "converged": 8}


@dataclass(frozen=True, eq=False)
class Design:
    """Nominal design: the truth plant, its reduced model and continuous-time laws."""

    truth: Plant
    reduced: ReducedModel
    smc_eps: float = 1.0

    @property
    def plant(self):
        """``(A, B, E, Cy)`` of the (nominal) truth plant."""
        return self.truth.state_space()

    @cached_property
    def metric(self) -> np.ndarray:
        """The full-state metric W of the thesis's weights: :math:`P^T P` with P the map
        to the thesis mesh's state (the identity for the thesis's own model), so that
        ``1e11 I`` means the same physical quantities on every plant."""
        P = self.truth.physical_state()
        return P.T @ P

    def state_weight(self, weight: float) -> np.ndarray:
        """The full-state weight ``weight * W`` seen by the reduced state (k x k)."""
        return projected_weight(self.reduced, weight, self.metric)

    @cached_property
    def lqr(self) -> Feedback:
        return lqr(self.reduced, metric=self.metric)

    @cached_property
    def smc(self) -> Feedback:
        return smc(self.reduced, eps=self.smc_eps, metric=self.metric)

    @cached_property
    def passive(self) -> Feedback:
        return passive(self.reduced.order)

    def feedback(self, name: str) -> Feedback:
        """The law called ``name`` ("passive", "lqr" or "smc")."""
        if name not in ("passive", "lqr", "smc"):
            raise ValueError(f"controller must be 'passive', 'lqr' or 'smc', got {name!r}")
        return getattr(self, name)

    def observer(self, kind: str = "thesis") -> Observer:
        """``"thesis"`` (full order, fed the load -- reproduces Table 2),
        ``"thesis-unfed"`` (the same without the load) or ``"kalman"``.

        The thesis's observer weight Q = I applies to the plant's own state: the thesis
        mesh's DOFs, or the converged plant's mass-normalized Ritz coordinates. (Its
        gain is tiny either way, |L| = 77 and 28: fed the load, it runs as a copy of
        the plant. Mapping Q = I from the thesis's DOFs instead is ill-posed: the
        converged plant's metric P^T P is singular, cond 7e18.)"""
        A, B, E, Cy = self.plant
        if kind in ("thesis", "thesis-unfed"):
            return thesis_observer(A, B, E, Cy, self.reduced, fed_load=kind == "thesis")
        if kind == "kalman":
            return kalman_observer(self.reduced)
        raise ValueError(f"observer must be 'thesis', 'thesis-unfed' or 'kalman', got {kind!r}")


def design(
    model: Plant | BeamModel | None = None,
    order: int = REDUCED_ORDER,
    smc_eps: float = 1.0,
    *,
    basis: str = "modal",
    **model_kwargs,
) -> Design:
    """Reduce a truth plant (default: the thesis's FE model) and design on it.

    Parameters
    ----------
    model : Plant, BeamModel or None
        A :class:`acld_gym.physics.plant.Plant`, a :class:`acld_gym.physics.model.BeamModel`
        (its FE model becomes the plant), or None to build one from ``model_kwargs``
        (:func:`acld_gym.physics.model.build_model`'s arguments).
    order : reduced order (thesis: 6).
    smc_eps : the continuous SMC's boundary layer.
    basis : coordinates of the reduced model (:data:`acld_gym.design.reduction.BASES`).

    Notes
    -----
    The laws are designed on first use.
    """
    if isinstance(model, Plant):
        if model_kwargs:
            raise ValueError("model_kwargs: give either a model or build_model keywords, not both")
        truth = model
    elif isinstance(model, BeamModel):
        if model_kwargs:
            raise ValueError("model_kwargs: give either a model or build_model keywords, not both")
        truth = fe_plant(model.params, model.mesh)
    elif model is None:
        truth = fe_plant(*resolve(**model_kwargs))
    else:
        raise ValueError(f"model must be a Plant, a BeamModel or None, got {type(model).__name__}")
    A, B, E, Cy = truth.state_space()
    red = schur_balanced_truncation(A, B, Cy, order, E=E, basis=basis)
    return Design(truth=truth, reduced=red, smc_eps=smc_eps)
