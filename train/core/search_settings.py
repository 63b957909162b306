"""The settings of ``vrs``, the vectorised random search (:mod:`train.core.search`): the
``model:`` mapping of its recipe, validated into :class:`RandomSearch`. Apart from the search
so that a config's validation (:mod:`train.config_model`) reads them without the search's
env and training loop."""

from __future__ import annotations

from dataclasses import dataclass

from acld_gym.util.validate import check_choice, check_int, check_real

__all__ = ["RandomSearch"]


@dataclass(frozen=True)
class RandomSearch:
    """Settings of ``vrs`` (the ``model:`` mapping of its YAML file).

    Attributes
    ----------
    n_directions : int
        Perturbation directions per iteration (2 x as many candidates).
    top_directions : int
        Directions used in the update (the best by max of their two scores).
    step_size : float
        ARS step size alpha (the update is divided by the scores' std).
    noise : float
        Perturbation std nu.
    relative : bool
        Scale step and perturbation by max(1, |theta| / sqrt(dim)): a step of the same
        relative size as the actor's gain grows (the boundary layer can thin out).
    objective : str
        Score of an episode with return R: ``"log"`` -log(-R) (per-load scale-free),
        ``"return"`` R itself.
    init_std : float
        Std of the random initial parameters (seeded).
    anneal : float
        Step size and noise fall linearly over the budget to this fraction of their
        initial values (1: constant), so the final actor jitters less.
    whiten : bool
        Estimate a whitening matrix (:func:`acld_gym.wrappers.whitening`) from the
        observations of a first round of candidate episodes (counted in the budget) and
        search the actor on the whitened observation. The scaled observation's components
        are strongly correlated (up to 0.999), which makes an isotropic search in w ill-conditioned.
    common_episodes : bool
        Every candidate of an iteration runs on the same episodes (loads and sensor
        noise; common random numbers), so a direction's +/- scores differ by the
        perturbation, not by the loads. False: independent episodes per candidate.
    """

    n_directions: int = 16
    top_directions: int = 8
    step_size: float = 0.02
    noise: float = 0.03
    relative: bool = True
    objective: str = "log"
    init_std: float = 0.1
    anneal: float = 1.0
    whiten: bool = False
    common_episodes: bool = True

    def __post_init__(self):
        check_int("model.n_directions", self.n_directions, 1, 10**6)
        check_int("model.top_directions", self.top_directions, 1, self.n_directions)
        check_real("model.step_size", self.step_size, 0.0, low_open=True)
        check_real("model.noise", self.noise, 0.0, low_open=True)
        check_real("model.init_std", self.init_std, 0.0)
        check_real("model.anneal", self.anneal, 0.0, 1.0)
        check_choice("model.objective", self.objective, ("log", "return"))
        for name in ("relative", "whiten", "common_episodes"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"model.{name} must be true or false, got {getattr(self, name)!r}")
