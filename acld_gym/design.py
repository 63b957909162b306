"""The thesis's design pipeline in one call: model -> reduction -> observer -> controllers.

Everything downstream (the reproduction, the environment's reference
policies) starts from a :class:`Design`, so the pipeline is written once.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

from .control import Feedback, lqr, passive, smc
from .model import BeamModel, build_model
from .observer import Observer, kalman_observer, thesis_observer
from .reduction import ReducedModel, schur_balanced_truncation

__all__ = ["Design", "design", "REDUCED_ORDER"]

#: Order of the reduced model (thesis sec. 3.3, Fig. 5).
REDUCED_ORDER = 6


@dataclass(frozen=True, eq=False)
class Design:
    """Nominal design: model, reduced model and continuous-time laws."""

    model: BeamModel
    reduced: ReducedModel
    smc_eps: float = 1.0

    @property
    def plant(self):
        """``(A, B, E, Cy)`` of the full model."""
        return self.model.state_space()

    @cached_property
    def lqr(self) -> Feedback:
        return lqr(self.reduced)

    @cached_property
    def smc(self) -> Feedback:
        return smc(self.reduced, eps=self.smc_eps)

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
        ``"thesis-unfed"`` (the same without the load) or ``"kalman"``."""
        A, B, E, Cy = self.plant
        if kind == "thesis":
            return thesis_observer(A, B, E, Cy, self.reduced, fed_load=True)
        if kind == "thesis-unfed":
            return thesis_observer(A, B, E, Cy, self.reduced, fed_load=False)
        if kind == "kalman":
            return kalman_observer(self.reduced)
        raise ValueError(f"observer must be 'thesis', 'thesis-unfed' or 'kalman', got {kind!r}")


def design(model: BeamModel | None = None, order: int = REDUCED_ORDER, smc_eps: float = 1.0,
           **model_kwargs) -> Design:
    """Build (or take) the model and reduce it; laws are designed on first use."""
    if model is None:
        model = build_model(**model_kwargs)
    elif model_kwargs:
        raise ValueError("model_kwargs: give either a model or build_model keywords, not both")
    A, B, E, Cy = model.state_space()
    red = schur_balanced_truncation(A, B, Cy, order, E=E)
    return Design(model=model, reduced=red, smc_eps=smc_eps)
