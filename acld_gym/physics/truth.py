"""The truth plants by name (``mesh=``): the thesis's mesh, or the mesh-converged beam read from
its versioned file or built (:mod:`acld_gym.physics.plant`)."""

from __future__ import annotations

from functools import lru_cache

from acld_gym.physics.krylov import REFINEMENT, build_converged_plant
from acld_gym.physics.params import BeamParameters
from acld_gym.physics.plant import Plant, thesis_plant
from acld_gym.physics.plant_cache import cached

__all__ = ["MESHES", "REFINEMENT", "converged_plant", "plant"]


#: Truth-plant presets of the ``mesh`` option.
MESHES = ("converged", "thesis")


@lru_cache(maxsize=4)
def converged_plant(
    dt: float = 1e-3, params: BeamParameters | None = None, refinement: int = REFINEMENT
) -> Plant:
    """The mesh-converged plant for control period ``dt`` [s] (module docstring).

    Read from its versioned file when one exists (:mod:`acld_gym.physics.plant_cache`: the
    default plant ships with the package), else built (about 0.5 s) and cached.

    Why a file: the Krylov vectors come from solves on the fine mesh, accurate to about
    1e-6 (relative; the systems are ill-conditioned near the resonances), so a plant
    built on another CPU's BLAS kernels differs in its coordinates at that level. The
    shipped file makes the default plant, and everything observed in its coordinates,
    bit-identical on every machine.

    Parameters
    ----------
    dt : control period [s]; the plant is accurate up to
        :func:`acld_gym.physics.plant.band_of` (dt).
    params : nominal parameters (default: the thesis's MATLAB values).
    refinement : refinement factor of the thesis mesh (default :data:`REFINEMENT`).
    """
    params = BeamParameters() if params is None else params
    return cached(
        params,
        float(dt),
        int(refinement),
        lambda: build_converged_plant(float(dt), params, int(refinement)),
    )


def plant(mesh: str = "converged", dt: float = 1e-3) -> Plant:
    """The nominal plant of ``mesh`` (:data:`MESHES`) for control period ``dt`` [s]."""
    if mesh == "converged":
        return converged_plant(float(dt))
    if mesh == "thesis":
        return thesis_plant()
    raise ValueError(f"mesh must be one of {list(MESHES)}, got {mesh!r}")
