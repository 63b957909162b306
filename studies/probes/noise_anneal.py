"""A probe of the PPO recipe with gSDE's exploration noise capped late in the run.

gSDE's noise is on the actor's gains, so the voltage's noise grows with the state: a
multiplicative noise, under which the best mean law is more cautious than the best
deterministic one (unlike additive noise, which leaves a linear-quadratic law unchanged).
The recipe's PPO (``train/recipes/ppo.yaml``, no entropy bonus) keeps whatever noise its
gradient leaves, and its deterministic actor is scored; the random search, which is ~0.01
above PPO on every level, shrinks its perturbations to 20 % over its budget.

This probe caps the actor's log std (every entry of gSDE's matrix) from ``--start`` of the
run on, linearly from the recipe's ``log_std_init`` down to ``--final`` at the run's end
(:class:`AnnealedNoisePolicy`, applied when SB3 draws a rollout's noise, so each rollout's
log-probabilities are those of the noise it was acted with). Everything else is the
recipe's, one run per seed, on any level (``--env-id``).

It prints one JSON line per seed: the run's validation cost (256 loads; the recipe's own
check), the final noise (the mean of exp(log std)) and ISE / LQR on the thesis cases
(``studies/probes/probe.py``). Not a test; 1-2 min per seed on one core::

    python studies/probes/noise_anneal.py --env-id ACLDBeamLab-v1 --seeds 0 1 2 3 4
    python studies/probes/noise_anneal.py --env-id ACLDBeamLab-v1 --seeds 0 1 --final -1
"""

from __future__ import annotations

import sys

import torch
from probe import one_run, run_recipe, seeds_main  # studies/probes/probe.py

from train.core import sb3_train
from train.core.sb3_policies import AsymmetricCriticPolicy


class AnnealedNoisePolicy(AsymmetricCriticPolicy):
    """The recipe's actor-critic whose log std is capped, at each rollout's noise draw
    (:meth:`reset_noise`, once per rollout), at ``log_std_init`` until the fraction
    ``start`` of ``rollouts`` draws, then linearly down to ``final`` at the last."""

    def __init__(self, *args, rollouts: int, start: float, final: float, **kwargs):
        self.rollouts, self.start, self.final = rollouts, start, final
        self.init = kwargs.get("log_std_init", 0.0)
        self.draws = 0
        super().__init__(*args, **kwargs)

    #: The mean of exp(log std) at the last rollout's draw (for the probe's line).
    last_std = float("nan")

    def reset_noise(self, n_envs: int = 1) -> None:
        if n_envs > 1:  # a rollout's draw (PPO.load / one-env rollouts: n_envs 1)
            self.draws += 1
            frac = (self.draws / self.rollouts - self.start) / max(1.0 - self.start, 1e-9)
            if frac > 0 and self.start < 1.0:
                cap = self.init + min(frac, 1.0) * (self.final - self.init)
                with torch.no_grad():
                    self.log_std.clamp_(max=cap)
        super().reset_noise(n_envs)
        AnnealedNoisePolicy.last_std = float(self.log_std.detach().exp().mean())


def run(seed: int, args) -> dict:
    cfg = one_run(None, base="ppo")
    n_envs, n_steps = cfg.n_envs, cfg.model["n_steps"]
    rollouts = (cfg.timesteps - cfg.whiten_steps) // (n_envs * n_steps) + 1
    # a config names its policy (train.config_model); the recipe's name builds this one
    sb3_train.AsymmetricCriticPolicy = AnnealedNoisePolicy
    cfg = one_run(
        None, {"rollouts": rollouts, "start": args.start, "final": args.final}, base="ppo"
    )
    line = run_recipe(cfg, seed, args.env_id, start=args.start, final=args.final)
    return {**line, "final_std": round(AnnealedNoisePolicy.last_std, 4)}


def add_arguments(p) -> None:
    p.add_argument("--env-id", default="ACLDBeamLab-v1")
    p.add_argument(
        "--start", type=float, default=0.5, help="fraction of the run (default 0.5; 1: no cap)"
    )
    p.add_argument("--final", type=float, default=-3.0, help="log std cap at the end (-3)")


if __name__ == "__main__":
    sys.exit(seeds_main(__doc__, run, add_arguments=add_arguments))
