"""The Gymnasium environments: the configuration, the registered presets, episode
ingredients, the one batched step, the single and batched envs, rendering and the SB3
adapter."""

from importlib import import_module

#: Public names, imported on first use (the SB3 adapter needs stable-baselines3).
_EXPORTS = {
    "ACLDBeamEnv": "beam_env",
    "ACLDBeamVectorEnv": "vector_env",
    "SB3VecEnv": "sb3",
    "EnvConfig": "config",
    "make_config": "config",
    "preset": "presets",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
