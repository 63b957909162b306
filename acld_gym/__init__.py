"""acld-gym: an ACLD cantilever (Rodriguez 2006) as a Gymnasium benchmark.

Importing the package registers ``ACLDBeam-v1`` (the mesh-converged beam) and
``ACLDBeam-v0`` (the thesis configuration: its mesh, design model and observers), both
observing in the canonical modal basis, the same on every machine;
``gym.make("acld_gym:ACLDBeam-v1")`` imports it by itself.

The subpackages follow the pipeline: :mod:`acld_gym.physics` (parameters, finite
elements, the truth plants) -> :mod:`acld_gym.design.pipeline` (reduction, observers, feedback,
sampling, simulation) -> :mod:`acld_gym.envs` (the Gymnasium environments);
:mod:`acld_gym.thesis.table2` reproduces the thesis; :mod:`acld_gym.util` holds the tools.
"""

from gymnasium.envs.registration import register, registry

__version__ = "0.2.0"

#: The current environment id.
ENV_ID = "ACLDBeam-v1"

# No max_episode_steps: the env truncates itself after episode_length / dt steps (its
# spec reports that count), so gym.make, make_vec and the SB3 adapter all follow
# episode_length and dt; max_episode_steps= can still shorten an episode.
if "ACLDBeam-v1" not in registry:
    register(id="ACLDBeam-v1", entry_point="acld_gym.envs.beam_env:ACLDBeamEnv",
             vector_entry_point="acld_gym.envs.vector_env:ACLDBeamVectorEnv")
if "ACLDBeam-v0" not in registry:
    register(id="ACLDBeam-v0", entry_point="acld_gym.envs.legacy:ACLDBeamEnvV0",
             vector_entry_point="acld_gym.envs.legacy:ACLDBeamVectorEnvV0")
