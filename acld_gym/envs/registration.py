"""The ids in gymnasium's registry, and what ``gym.make`` was asked.

Every id registers the step count of its episodes, ``gym.spec(id).max_episode_steps``
(1000: ``episode_length / dt`` of the id's configuration), for the tools that read the
registry; the spec of a ``make_vec`` env (sync or async) reports the count of the keywords
it was made with. The env truncates itself after ``episode_length / dt`` steps, whatever
its keywords make that (``gym.make(id, episode_length=1.5)``: 1500 steps), so gymnasium's
own ``make`` and ``make_vec`` must not add a ``TimeLimit`` of the registered count: it
would cut a longer episode at 1000 steps and report 1000 for a shorter one. A
:class:`RegisteredSpec` therefore gives those two functions no limit (exactly as before
the count was registered: the same wrappers, the same episodes) and every other reader the
count. ``gym.make(id, max_episode_steps=n)`` still adds gymnasium's ``TimeLimit`` of n
steps; :func:`make_limit` reads that n, so that the env can refuse an n its episode
never reaches (:func:`acld_gym.envs.conflicts.made_spec`).

Both look at the calling frame, the one way to tell gymnasium's ``make`` from other
readers of the same registry entry; they are tested against the installed gymnasium
(tests/envs/test_conflicts.py), so a gymnasium that renames ``make`` fails a test instead
of silently changing the episodes.
"""

from __future__ import annotations

import dataclasses
import sys
import warnings
from types import FrameType

from gymnasium.envs import registration as _gym_registration
from gymnasium.envs.registration import EnvSpec

from acld_gym.envs.ids import ENTRY_POINT, PRESETS, VECTOR_ENTRY_POINT, kwargs_steps

__all__ = ["RegisteredSpec", "register_presets", "make_limit", "plain_spec"]

#: The code of gymnasium's ``make`` and ``make_vec`` (the readers that apply a limit).
_MAKERS = (_gym_registration.make.__code__, _gym_registration.make_vec.__code__)


class RegisteredSpec(EnvSpec):
    """An :class:`gymnasium.envs.registration.EnvSpec` whose ``max_episode_steps`` is the
    step count of the episodes its ``kwargs`` give
    (:func:`acld_gym.envs.ids.kwargs_steps`: 1000 for a registered id; a ``make_vec``
    env's spec carries the keywords it was made with) for every reader except gymnasium's
    ``make`` and ``make_vec``, which see the spec's own limit (None for a registered id: the
    env truncates itself)."""

    @property
    def max_episode_steps(self) -> int | None:
        limit = self.__dict__.get("_limit")
        if sys._getframe(1).f_code in _MAKERS:
            return limit
        return kwargs_steps(self.kwargs, limit)

    @max_episode_steps.setter
    def max_episode_steps(self, value: int | None) -> None:
        self.__dict__["_limit"] = value


#: Gymnasium warns on ``gym.make`` of an id whose name has a higher version registered
#: ("The environment ACLDBeam-v0 is out of date. You should consider upgrading to version
#: `v1`"). Here v0 is not an old release but a level in its own right, the thesis
#: configuration, scored on the leaderboard beside v1: that one warning, for the package's
#: own ``-v0`` ids only, is not shown.
OUT_OF_DATE = r"(?s).*The environment ACLDBeam[A-Za-z]*-v0 is out of date"


def register_presets() -> None:
    """Register every id of :data:`acld_gym.envs.ids.PRESETS` with gymnasium (once), with
    its episode's step count as ``gym.spec(id).max_episode_steps`` for the tools that read
    the registry. The env truncates itself after ``episode_length / dt`` steps, so
    gymnasium's ``make`` and ``make_vec`` add no ``TimeLimit`` of that count
    (:class:`RegisteredSpec`): ``gym.make``, ``make_vec`` and the SB3 adapter all follow
    ``episode_length`` and ``dt``; ``max_episode_steps=`` can still shorten an episode (a
    longer one is refused)."""
    warnings.filterwarnings("ignore", message=OUT_OF_DATE, category=DeprecationWarning)
    registry = _gym_registration.registry
    for env_id, kwargs in PRESETS.items():
        if env_id not in registry:
            registry[env_id] = RegisteredSpec(
                id=env_id,
                entry_point=ENTRY_POINT,
                vector_entry_point=VECTOR_ENTRY_POINT,
                kwargs=dict(kwargs),
            )


def make_limit(frame: FrameType | None) -> int | None:
    """The ``max_episode_steps`` argument of gymnasium's ``make`` if ``frame`` is a call of
    it (None otherwise, or when it was not given)."""
    if frame is None or frame.f_code is not _gym_registration.make.__code__:
        return None
    return frame.f_locals.get("max_episode_steps")


def plain_spec(spec: EnvSpec, steps: int) -> EnvSpec:
    """A plain :class:`EnvSpec` with the fields of ``spec`` and ``max_episode_steps=steps``
    (what an env made from it reports)."""
    values = {f.name: getattr(spec, f.name) for f in dataclasses.fields(spec) if f.init}
    return EnvSpec(**{**values, "max_episode_steps": int(steps)})
