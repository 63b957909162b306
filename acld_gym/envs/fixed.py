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

__all__ = ["DERIVED", "fixed_names", "FixedSettings"]


#: What an env derives from its configuration, fixed with it.
DERIVED = frozenset(
    {"nom", "harmonic_modes", "max_steps", "max_episode_steps", "horizon", "num_envs"}
)


def fixed_names(config_class) -> frozenset[str]:
    """The attributes fixed once an env of ``config_class`` (a dataclass:
    :class:`acld_gym.envs.config.EnvConfig`) is built: its configuration, every field of
    the configuration but ``load_case``, and what the env derived from them
    (:data:`DERIVED`)."""
    fields = {f.name for f in dataclasses.fields(config_class)} - {"load_case"}
    return frozenset(fields | DERIVED | {"config"})


class FixedSettings:
    """Mixin: after construction (once ``_batch`` is set), assigning an attribute of
    :attr:`FIXED_NAMES` raises ``AttributeError`` naming it. A subclass sets
    :attr:`FIXED_NAMES` (:class:`acld_gym.envs.config.ConfigAttributes`:
    ``fixed_names(EnvConfig)``)."""

    #: The attributes fixed at construction (:func:`fixed_names`).
    FIXED_NAMES: frozenset[str] = frozenset()

    def __setattr__(self, name: str, value) -> None:
        if "_batch" in self.__dict__ and name in type(self).FIXED_NAMES:
            raise AttributeError(
                f"{type(self).__name__}.{name} is fixed at construction (the env was built "
                f"for it; a new value would be ignored or unchecked): make a new env with "
                f"{name}=... instead"
            )
        super().__setattr__(name, value)
