"""acld-gym: an ACLD cantilever (Rodriguez 2006) as a Gymnasium benchmark.

Importing the package registers ``ACLDBeam-v1`` (the mesh-converged beam), ``ACLDBeam-v0``
(the thesis configuration: its mesh, design model and observers) and the difficulty presets
(:mod:`acld_gym.envs.presets`), all configurations of one env class observing in the
canonical modal basis, the same on every machine; ``gym.make("acld_gym:ACLDBeam-v1")``
imports it by itself.

The subpackages follow the pipeline: :mod:`acld_gym.physics` (parameters, finite
elements, the truth plants, loads) -> :mod:`acld_gym.design` (reduction, observers,
feedback, sampling, simulation, the nominal design) -> :mod:`acld_gym.envs` (the Gymnasium
environments); :mod:`acld_gym.thesis.table2` reproduces the thesis; :mod:`acld_gym.util`
holds the tools.
"""

from acld_gym.envs.registration import register_presets

__version__ = "0.26.0"

#: The current environment id.
ENV_ID = "ACLDBeam-v1"

register_presets()
