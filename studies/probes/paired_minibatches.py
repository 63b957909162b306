"""A probe of the PPO recipe (acld-gym 0.15.0) with each antithetic pair in one minibatch.

The recipe's sub-envs ``2i`` and ``2i + 1`` run the same loads and sensor noise with
opposite gain noise (``paired_loads``, ``antithetic_noise``), so what the load does to the
pair's advantages cancels in the sum of their policy-gradient terms, as in the random
search's difference of returns. SB3's ``RolloutBuffer.get`` deals the rollout's samples
to minibatches in a random order of samples, which splits most pairs across minibatches:
the cancellation then happens over an epoch's four gradient steps, not within each.
:class:`PairedRolloutBuffer` deals them in a random order of pairs (a pair's two samples
of the same step side by side), so every minibatch holds whole pairs. Everything else is
the recipe's, one run per seed.

It prints one JSON line per seed (``studies/probes/probe.py``). Not a test; about half a
minute per seed on two cores::

    python studies/probes/paired_minibatches.py --seeds 0 1 2 3 4

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table).
"""

from __future__ import annotations

import sys

import numpy as np
from probe import one_run, run_recipe, seeds_main  # studies/probes/probe.py, beside this script
from stable_baselines3.common.buffers import RolloutBuffer

#: The recipe's rollout fields, flattened to (sub-env, step) order before the minibatches.
FIELDS = ("observations", "actions", "values", "log_probs", "advantages", "returns")


def paired_permutation(n_steps: int, n_envs: int, rng=np.random) -> np.ndarray:
    """A random order of the rollout's ``n_steps * n_envs`` samples, flattened sub-env by
    sub-env (SB3's ``swap_and_flatten``: sample ``env * n_steps + t``), in which the
    samples of sub-envs ``2i`` and ``2i + 1`` at the same step t are adjacent, the pair
    first; so a minibatch of an even size starting at an even position holds whole pairs."""
    if n_envs % 2:
        raise ValueError(f"n_envs must be even (sub-envs in pairs), got {n_envs}")
    order = rng.permutation(n_steps * n_envs // 2)  # (pair, step) in pair-major order
    first = (order // n_steps) * 2 * n_steps + order % n_steps  # sub-env 2i, step t
    return np.stack([first, first + n_steps], axis=1).reshape(-1)


class PairedRolloutBuffer(RolloutBuffer):
    """SB3's ``RolloutBuffer`` whose minibatches hold whole antithetic pairs
    (:func:`paired_permutation`); its batch size must be even."""

    def get(self, batch_size: int | None = None):
        assert self.full, ""
        n = self.buffer_size * self.n_envs
        batch_size = n if batch_size is None else batch_size
        if batch_size % 2:
            raise ValueError(f"batch_size must be even (whole pairs), got {batch_size}")
        indices = paired_permutation(self.buffer_size, self.n_envs)
        if not self.generator_ready:
            for name in FIELDS:
                self.__dict__[name] = self.swap_and_flatten(self.__dict__[name])
            self.generator_ready = True
        for start in range(0, n, batch_size):
            yield self._get_samples(indices[start : start + batch_size])


def config():
    """``train/recipes/ppo.yaml``'s config, one run, with :class:`PairedRolloutBuffer`."""
    return one_run(None, base="ppo", rollout_buffer_class=PairedRolloutBuffer)


def main(argv: list[str] | None = None) -> int:
    return seeds_main(
        __doc__, lambda seed, a: run_recipe(config(), seed, paired_minibatches=True), argv
    )


if __name__ == "__main__":
    sys.exit(main())
