"""Settings an env is built for, refused when assigned afterwards.

An env derives its plant, observer, step tables and random-load targets from its
configuration once, at construction. Assigning one of those settings to a built env
(``env.unwrapped.harmonic_modes = ...``, ``env.unwrapped.config = ...``, a new
``temperature`` attribute) would be ignored, or would bypass the checks of
:mod:`acld_gym.envs.conflicts` (a harmonic target the sub-step integration cannot resolve),
so :class:`FixedSettings` refuses it with one ``AttributeError`` naming it. ``load_case``
stays settable where the env has a setter for it (the vector env: SB3's ``set_attr``).
"""

from __future__ import annotations

import dataclasses
import functools

__all__ = ["fixed_names", "FixedSettings"]


@functools.cache
def fixed_names() -> frozenset[str]:
    """The attributes fixed once an env is built: its configuration, every configuration
    field (but ``load_case``), and what the env derived from them."""
    from acld_gym.envs.config import EnvConfig  # (config.py's ConfigAttributes uses this)

    fields = {f.name for f in dataclasses.fields(EnvConfig)} - {"load_case"}
    derived = {"nom", "harmonic_modes", "max_steps", "max_episode_steps", "horizon", "num_envs"}
    return frozenset(fields | derived | {"config"})


class FixedSettings:
    """Mixin: after construction (once ``_batch`` is set), assigning an attribute of
    :func:`fixed_names` raises ``AttributeError`` naming it."""

    def __setattr__(self, name: str, value) -> None:
        if "_batch" in self.__dict__ and name in fixed_names():
            raise AttributeError(
                f"{type(self).__name__}.{name} is fixed at construction (the env was built "
                f"for it; a new value would be ignored or unchecked): make a new env with "
                f"{name}=... instead"
            )
        super().__setattr__(name, value)
