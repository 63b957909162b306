"""A probe of the PPO recipe (acld-gym 0.15.0) for the stretch goal: each rollout's
advantages divided by their RMS over the last episode's rollouts, not by their own
standard deviation, so that the phases of an episode weigh in the policy gradient as they
weigh in its return.

The recipe's 256 sub-envs start their 1000-step episodes together and end them together (a
fixed 1 s horizon), so each 64-step rollout holds the same 64 ms of every sub-env's
episode, and the size of its advantages changes from one rollout to the next (their
standard deviation over rollouts 25-48 of a 1M-step run of the recipe on seed 0: 21-386).
SB3 divides each minibatch's advantages by their standard deviation, which makes every
rollout weigh alike in the policy gradient, where the episode's return, the random
search's score, weighs each 64 ms by its size. Without any normalization
(``ablation_ppo_no_adv_norm_v015.yaml``) the entropy coefficient, set against advantages
of unit size, is out of scale. :class:`PhaseScaledRolloutBuffer` keeps the unit size on
average over an episode and the rollouts' ratios within it: after SB3 computes a rollout's
advantages, it subtracts their mean and divides them by the RMS of the last :data:`WINDOW`
rollouts' standard deviations (16 rollouts of 64 steps: one 1000-step episode), and the
model's own normalization is off. Everything else is the recipe's, one run per seed.

It prints one JSON line per seed (``studies/probes/probe.py``). Not a test; about half a
minute per seed on two cores::

    python studies/probes/phase_weights.py --seeds 0 1 2 3 4

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table).
"""

from __future__ import annotations

import sys
from collections import deque

import numpy as np
from probe import one_run, run_recipe, seeds_main  # studies/probes/probe.py, beside this script
from stable_baselines3.common.buffers import RolloutBuffer

#: Rollouts in the RMS: one 1000-step episode of the recipe's 64-step rollouts.
WINDOW = 16


class PhaseScaledRolloutBuffer(RolloutBuffer):
    """SB3's ``RolloutBuffer`` whose advantages, once computed, are centred and divided by
    the RMS of the standard deviations of the last :data:`WINDOW` rollouts' advantages
    (this one's included); the model's ``normalize_advantage`` must be off."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.variances: deque[float] = deque(maxlen=WINDOW)

    def compute_returns_and_advantage(self, last_values, dones) -> None:
        super().compute_returns_and_advantage(last_values, dones)
        centred = self.advantages - self.advantages.mean()
        self.variances.append(float(np.mean(centred**2)))
        self.advantages = centred / (np.sqrt(np.mean(self.variances)) + 1e-8)


def config():
    """``train/recipes/ppo.yaml``'s config, one run, with
    :class:`PhaseScaledRolloutBuffer` and SB3's per-minibatch normalization off."""
    return one_run(
        None, base="ppo", rollout_buffer_class=PhaseScaledRolloutBuffer, normalize_advantage=False
    )


def main(argv: list[str] | None = None) -> int:
    return seeds_main(
        __doc__, lambda seed, a: run_recipe(config(), seed, phase_window=WINDOW), argv
    )


if __name__ == "__main__":
    sys.exit(main())
