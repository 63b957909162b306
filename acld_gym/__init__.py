"""acld-gym: an ACLD cantilever (Rodriguez 2006) as a Gymnasium benchmark.

Importing the package registers ``ACLDBeam-v0``; ``gym.make("acld_gym:ACLDBeam-v0")``
imports it by itself.
"""

from gymnasium.envs.registration import register, registry

__version__ = "0.1.0"

if "ACLDBeam-v0" not in registry:
    register(id="ACLDBeam-v0", entry_point="acld_gym.env:ACLDBeamEnv",
             vector_entry_point="acld_gym.vector_env:ACLDBeamVectorEnv", max_episode_steps=1000)
