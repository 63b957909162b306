r"""Small-signal stability of the reference policies on randomized plants.

About rest no voltage limit or switching is active, and every reference policy is a
linear law :math:`V = -K \hat x_r`
(:meth:`baselines.policies.LQRPolicy.small_signal_gain`). With the env's observer
(:class:`acld_gym.design.observer.DiscreteObserver`: measurement update :math:`L_c`,
prediction gain :math:`L_p`) and a sampled plant :math:`(A_d, B_d, c)`, one period of
the loop is linear in :math:`(x, \hat x)`:

.. math::

    V &= -K\,(\hat x + L_c (c^T x - C \hat x)), \\
    x^+ &= A_d x + B_d V, \\
    \hat x^+ &= A \hat x + B V + L_p (c^T x - C \hat x),

and the policy is stable on that plant when the spectral radius of this map is below 1.
:func:`corner_study` evaluates it at every corner of the env's parameter box (each
randomized parameter at :math:`e^{\pm 3\sigma}`, 1024 plants), the worst case of a
multiplicative perturbation; ``python -m baselines.robustness`` prints the table quoted
in ``docs/baselines.md``.
"""

from __future__ import annotations

import argparse
import itertools
import sys
from dataclasses import replace

import numpy as np

from acld_gym.design.discrete import SampledSystem, discretize
from acld_gym.design.nominal import NominalDesign, nominal_design
from acld_gym.design.observer import DiscreteObserver
from acld_gym.envs.config import PARAM_NOISE_MAX, EnvConfig
from acld_gym.physics.truth import MESHES
from acld_gym.physics.uncertainty import PARAM_NOISE_CLIP, RANDOMIZED
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type, check_real

from .analysis.linear import LinearLaw, ObserverLoop
from .policies import LQRPolicy, MPCPolicy, SMCPolicy

#: The largest ``--param-noise``: the range of the env's ``param_noise_max``
#: (:class:`acld_gym.envs.config.EnvConfig`), within which every corner is a physical beam.
PARAM_NOISE_LIMIT = EnvConfig.__dataclass_fields__["param_noise_max"].metadata["high"]

__all__ = ["closed_loop_matrix", "spectral_radius", "corner_plants", "corner_study", "main"]


def closed_loop_matrix(
    plant: SampledSystem, output: np.ndarray, observer: DiscreteObserver, gain: np.ndarray
) -> np.ndarray:
    """The loop's one-period map on ``[x, xhat]`` (module docstring): the observer loop of
    :class:`baselines.analysis.linear.ObserverLoop` with the law written on the prior
    estimate and the measurement, :math:`V = h_x^T \\hat x + h_y y`."""
    k = observer.n
    lc, C = observer.Lc[:, 0], observer.C[0]
    h = np.append(-(gain - (gain @ lc) * C), -(gain @ lc))  # V = h . [xhat, y]
    loop = ObserverLoop(
        plant=plant,
        output=output,
        observer=observer,
        obs_map=np.eye(k + 1),
        observer_load=np.zeros(k),
    )
    return loop.closed_loop(LinearLaw(gain=h, offset=0.0))


def spectral_radius(
    plant: SampledSystem,
    nom: NominalDesign,
    gain: np.ndarray,
    observer: DiscreteObserver | None = None,
) -> float:
    """Spectral radius of the small-signal loop of ``gain`` on ``plant`` (default observer:
    the nominal Kalman filter)."""
    obs = nom.kalman if observer is None else observer
    return float(
        np.max(np.abs(np.linalg.eigvals(closed_loop_matrix(plant, nom.output, obs, gain))))
    )


def corner_plants(nom: NominalDesign, param_noise: float):
    """The sampled plants at the corners of the parameter box: each of
    :data:`acld_gym.physics.uncertainty.RANDOMIZED` times :math:`e^{\\pm 3\\sigma}` (generator)."""
    param_noise = check_real("param_noise", param_noise, 0.0, PARAM_NOISE_LIMIT)
    truth = nom.truth
    f = float(np.exp(PARAM_NOISE_CLIP * param_noise))
    for signs in itertools.product((-1, 1), repeat=len(RANDOMIZED)):
        p = replace(
            truth.params,
            **{
                name: getattr(truth.params, name) * f**s
                for name, s in zip(RANDOMIZED, signs, strict=True)
            },
        )
        A, B, E, _ = truth.state_space(p)
        yield signs, discretize(A, B, E, nom.plant.dt, 1)


def corner_study(nom: NominalDesign, policies: dict, param_noise: float) -> dict[str, dict]:
    """Per policy: ``{"nominal": radius, "worst": radius, "unstable": count, "corners": n}``
    over the corners of the box of ``param_noise`` (:func:`corner_plants`)."""
    check_real("param_noise", param_noise, 0.0, PARAM_NOISE_LIMIT)  # before any work
    gains = {name: pol.small_signal_gain() for name, pol in policies.items()}
    out = {
        name: {
            "nominal": spectral_radius(nom.plant, nom, g),
            "worst": 0.0,
            "unstable": 0,
            "corners": 0,
        }
        for name, g in gains.items()
    }
    for _, plant in corner_plants(nom, param_noise):
        for name, g in gains.items():
            r = spectral_radius(plant, nom, g)
            rec = out[name]
            rec["worst"] = max(rec["worst"], r)
            rec["unstable"] += int(r >= 1.0)
            rec["corners"] += 1
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog=prog("python -m baselines.robustness"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--mesh", choices=MESHES, nargs="+", default=list(MESHES))
    p.add_argument(
        "--param-noise",
        type=arg_type(float, 0.0, PARAM_NOISE_LIMIT),
        default=None,
        help=(
            "relative std of the parameters, the box being +/-3 std (0 to "
            f"{PARAM_NOISE_LIMIT:g}, the env's param_noise_max range; default: the env's "
            "bound for the mesh)"
        ),
    )
    args = p.parse_args(argv)
    print("| mesh | param_noise | policy | nominal | worst corner | unstable corners |")
    print("|---|---|---|---|---|---|")
    for mesh in args.mesh:
        nom = nominal_design(mesh=mesh)
        sigma = PARAM_NOISE_MAX[mesh] if args.param_noise is None else args.param_noise
        pols = {cls.name: cls(nom=nom) for cls in (LQRPolicy, SMCPolicy, MPCPolicy)}
        for name, rec in corner_study(nom, pols, sigma).items():
            print(
                f"| {mesh} | {sigma:g} | {name} | {rec['nominal']:.5f} | {rec['worst']:.5f} | "
                f"{rec['unstable']} of {rec['corners']} |"
            )
    return 0


if __name__ == "__main__":
    from acld_gym.util.validate import run_main

    sys.exit(run_main(main))
