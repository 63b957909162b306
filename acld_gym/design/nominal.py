"""The nominal design of the environment: the design model sampled at the control period,
the observers on it and the fixed observation scales, with the nominal truth plant the env
samples. Observers and baselines know this design; the env's plant may differ from it
(parameter noise, temperature), which is the model mismatch they face.

:func:`nominal_design` builds it (cached: the env, its vector version and the baselines
share one design per setting).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from acld_gym.design.discrete import SampledSystem, discretize
from acld_gym.design.feedback import THESIS_LQR_WEIGHT, Feedback, discrete_lqr_gain
from acld_gym.design.observer import (
    MODEL_STD,
    DiscreteObserver,
    discrete_kalman,
    discrete_thesis,
)
from acld_gym.design.pipeline import DESIGN_ORDER, Design, design
from acld_gym.design.reduction import BASES
from acld_gym.design.simulate import simulate
from acld_gym.physics.loads import thesis_load
from acld_gym.physics.plant import Plant
from acld_gym.physics.truth import MESHES
from acld_gym.physics.truth import plant as truth_plant
from acld_gym.util.blas import one_blas_thread

__all__ = ["NominalDesign", "nominal_design", "SENSOR_NOISE_M"]


#: Default tip-sensor noise std [m]: 0.1 um, the resolution of a laser displacement
#: sensor. (With 1 um the high-gain LQR turns the noise into voltage jitter and the
#: thesis's settling times are not reached.)
SENSOR_NOISE_M = 1e-7


@dataclass(frozen=True, eq=False)
class NominalDesign:
    """The nominal design for one control period: what observers and baselines know,
    and the nominal truth plant the env samples. ``xr_scale`` are the fixed observation
    scales: each reduced state's peak magnitude in the passive response to thesis case 1."""

    design: Design
    plant: SampledSystem
    reduced: SampledSystem
    kalman: DiscreteObserver
    thesis: DiscreteObserver
    xr_scale: np.ndarray
    mesh: str
    basis: str

    @property
    def truth(self) -> Plant:
        """The nominal truth plant (continuous, second-order form)."""
        return self.design.truth

    @property
    def output(self) -> np.ndarray:
        """Tip-deflection row of the truth plant's state, y = output @ x [m]."""
        return self.design.plant[3][0]

    @property
    def modes(self) -> np.ndarray:
        """Damped natural frequencies of the nominal truth plant [rad/s], ascending."""
        return self.design.truth.natural_frequencies()

    def lqr_gain(self, weight: float = THESIS_LQR_WEIGHT) -> np.ndarray:
        r"""The discrete LQR gain K (1, k) on the sampled reduced model, V = -K x_r, with the
        thesis's weights :math:`Q = w\,S_R^T S_R`, R = 1 (eqs. 65-67; ``weight`` = w)."""
        K, _ = discrete_lqr_gain(
            self.reduced.Ad, self.reduced.Bd, self.design.state_weight(weight), np.eye(1)
        )
        return K

    def lqr_law(self, weight: float = THESIS_LQR_WEIGHT) -> Feedback:
        """The sampled LQR as a voltage law on the reduced state, V = -K x_r
        (:meth:`lqr_gain`): the LQR baseline's, and the ``"lqr"`` reward scale's."""
        K = self.lqr_gain(weight)[0]
        return Feedback(a=K, s=np.zeros_like(K), c=0.0, eps=1.0, name="lqr")

    def observer(self, kind: str) -> DiscreteObserver:
        """The sampled observer ``"kalman"`` or ``"thesis"``."""
        if kind not in ("kalman", "thesis"):
            raise ValueError(f"observer must be 'kalman' or 'thesis', got {kind!r}")
        return self.kalman if kind == "kalman" else self.thesis


@lru_cache(maxsize=8)
def nominal_design(
    dt: float = 1e-3,
    substeps: int = 10,
    sensor_std: float = SENSOR_NOISE_M,
    load_std: float = 1.0,
    mesh: str = "converged",
    basis: str = "modal",
    model_std: float = MODEL_STD,
) -> NominalDesign:
    """Nominal design of the ``mesh`` plant (:data:`acld_gym.physics.truth.MESHES`) sampled at
    ``dt``, with the design order :data:`acld_gym.design.pipeline.DESIGN_ORDER` and the Kalman
    filter's model-error noise ``model_std`` (cached: the env, its vector version and
    the baselines share it).

    Built on one BLAS thread (:mod:`acld_gym.util.blas`) whatever the caller's setting: on
    some CPUs' kernels one thread and two round differently (an AMD EPYC with OpenBLAS's
    Haswell kernels), and the design is cached, so the env's observer and scales would
    otherwise depend on the threads of whichever call built it first."""
    if basis not in BASES:
        raise ValueError(f"basis must be one of {list(BASES)}, got {basis!r}")
    if mesh not in MESHES:
        raise ValueError(f"mesh must be one of {list(MESHES)}, got {mesh!r}")
    with one_blas_thread():
        return _build(dt, substeps, sensor_std, load_std, mesh, basis, model_std)


def _build(dt, substeps, sensor_std, load_std, mesh, basis, model_std) -> NominalDesign:
    """:func:`nominal_design`'s work, its arguments checked."""
    d = design(truth_plant(mesh, dt), order=DESIGN_ORDER[mesh], basis=basis)
    A, B, E, Cy = d.plant
    sd = discretize(A, B, E, dt, substeps)
    r = d.reduced
    sr = discretize(r.A, r.B, r.E, dt, substeps)
    kal = discrete_kalman(
        sr.Ad, sr.Bd, sr.Ed, r.C, load_std=load_std, sensor_std=sensor_std, model_std=model_std
    )
    cont = d.observer("thesis")
    # Held-input matrix of the thesis gain: int_0^dt e^{As} ds L (columnwise ZOH).
    sl = discretize(A, cont.L, E, dt, 1)
    th = discrete_thesis(sd.Ad, sl.Bd, sd.Bd, Cy, cont)
    res = simulate(A, B, E, Cy, cont, d.passive, thesis_load(1), t_end=0.2, v_max=None)
    scale = np.abs(res.xr).max(axis=0)
    return NominalDesign(
        design=d,
        plant=sd,
        reduced=sr,
        kalman=kal,
        thesis=th,
        xr_scale=scale,
        mesh=mesh,
        basis=basis,
    )
