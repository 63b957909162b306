"""An agent's memory of its own commands: what a policy trained with the env option
``observe_commands`` (:class:`acld_gym.envs.config.EnvConfig`) reads besides the plain
observation, carried by the policy itself so that it runs on the plain env.

On a rig with a computation delay (``actuator_delay`` d > 0) the command of step k drives
the patch in step k + d: after a step, the last d commands are still in flight. The
engineer's delay-aware design has them in its state; the thesis's observer, and so the
``"estimate"`` observation, does not (the ``"measurement"`` observation ends with the
newest). A policy that knows its own commands needs no help from the env to have them:
:class:`CommandMemory` keeps them in SB3's recurrent-policy ``state`` (reset where
``episode_start`` is true, as the env's delay line is at reset), and appends the ones the
training env appended (:func:`acld_gym.envs.step.commands_in_flight`), in the env's order
and units, to the observation before the actor reads it. The evaluators pass the state
back at every step (:func:`baselines.evaluation.rollout.rollout`); a caller of ``predict``
must too, as with any SB3 recurrent policy.
"""

from __future__ import annotations

import numpy as np

from acld_gym.envs.limits import MAX_DELAY
from acld_gym.envs.presets import preset
from acld_gym.envs.step import observed_commands
from acld_gym.physics.actuator import V_LIMIT

__all__ = ["CommandMemory", "command_memory", "memory_of"]


class CommandMemory:
    """The last ``memory`` commands of each env, the oldest first, in units of
    :data:`acld_gym.physics.actuator.V_LIMIT` (the env's clip of the action); the oldest
    ``observed`` of them are appended to the observation.

    Parameters
    ----------
    memory : int
        The commands kept, the rig's ``actuator_delay`` (1 .. MAX_DELAY).
    observed : int
        The oldest of them the observation gets, 1 .. ``memory``
        (:func:`acld_gym.envs.step.commands_in_flight`).
    """

    def __init__(self, memory: int, observed: int):
        for name, value, low in (("memory", memory, 1), ("observed", observed, 1)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                raise ValueError(f"{name} must be an integer, got {value!r}")
            if not low <= value <= MAX_DELAY:
                raise ValueError(f"{name} must be in [{low}, {MAX_DELAY}], got {value!r}")
        if observed > memory:
            raise ValueError(f"observed must be at most memory ({memory}), got {observed!r}")
        self.memory, self.observed = int(memory), int(observed)

    def as_dict(self) -> dict[str, int]:
        """The metadata's ``commands`` field (:mod:`train.agent_schema`)."""
        return {"memory": self.memory, "observed": self.observed}

    def observe(self, obs: np.ndarray, state, episode_start) -> tuple[np.ndarray, np.ndarray]:
        """``(x, state)``: the observations ``obs`` (n, d) with the remembered commands
        appended (n, d + observed), and the memory (n, memory) with the rows whose
        ``episode_start`` is true (every row if ``state`` is None) at rest. ``ValueError``
        naming ``state`` if it is not this memory's for n envs, or ``episode_start`` if it
        is not n flags."""
        n = obs.shape[0]
        if state is None:
            state = np.zeros((n, self.memory), np.float32)
        else:
            state = np.asarray(state, dtype=np.float32)
            if state.shape != (n, self.memory):
                raise ValueError(
                    f"state: expected the policy's last state, shape ({n}, {self.memory}) "
                    f"(its last {self.memory} commands for {n} observations), got "
                    f"shape {state.shape}"
                )
            state = state.copy()
        if episode_start is not None:
            start = np.asarray(episode_start, dtype=bool).reshape(-1)
            if start.shape != (n,):
                raise ValueError(
                    f"episode_start: expected {n} flags (one per observation), got shape "
                    f"{np.shape(episode_start)}"
                )
            state[start] = 0.0
        x = np.concatenate([obs, state[:, : self.observed].astype(obs.dtype)], axis=1)
        return x, state

    def remember(self, state: np.ndarray, volts: np.ndarray) -> np.ndarray:
        """The memory after commanding ``volts`` (n,) or (n, 1) [V]: shifted by one, the
        clipped command last (what the env's delay line holds)."""
        v = np.clip(np.asarray(volts, dtype=np.float64).reshape(-1), -V_LIMIT, V_LIMIT)
        out = np.empty_like(state)
        out[:, :-1] = state[:, 1:]
        out[:, -1] = v / V_LIMIT
        return out


def command_memory(env_id: str, env_kwargs: dict | None) -> CommandMemory | None:
    """The memory of a policy trained on ``env_id`` with ``env_kwargs``: None unless
    ``observe_commands`` appends commands there (a delay, and not only the newest command
    in the ``"measurement"`` observation, which has it)."""
    return memory_of(preset(env_id, **dict(env_kwargs or {})))


def memory_of(config) -> CommandMemory | None:
    """The memory of a policy trained on the env of ``config`` (an
    :class:`acld_gym.envs.config.EnvConfig`): None unless its observation appends commands
    (:func:`acld_gym.envs.step.observed_commands`)."""
    observed = observed_commands(config)
    return CommandMemory(config.actuator_delay, observed) if observed else None
