"""What the env's objective leaves to a nonlinear law beyond the linear ones.

The PPO recipe and the random search return saturated linear laws; issue 20's stretch goal
asks PPO or SAC to beat the random search on the ISE of every case. A causal law that is
not linear is the certainty-equivalent MPC of the env's own reward: on the Kalman
estimate, over a horizon of H steps, it minimises

.. math:: \\sum_{j=1}^{H} (\\hat y_{k+j} / 1\\ \\mathrm{mm})^2
   + \\rho \\sum_{i=0}^{H-1} (V_{k+i} / 120\\ \\mathrm{V})^2, \\qquad |V| \\le 120\\ \\mathrm{V},

which for :math:`\\rho = \\lambda` (the env's ``lam``, 0.01) is the env's step cost with its
default ``y_ref`` of 1 mm (:func:`acld_gym.envs.step.reward_terms`) up to the estimate, the
horizon and each load's constant scale. It is :class:`baselines.policies.MPCPolicy`
without its robustness weight (``state_weight=0``), on the env's nominal model; at
:math:`\\rho = \\lambda` it is :class:`baselines.policies.RewardMPCPolicy`, the
``mpc_reward`` row of ``python -m train.compare``'s tables. Being
certainty-equivalent and of finite horizon it is not the optimum of the objective, so a
weight :math:`\\rho` below :math:`\\lambda` may serve the objective better; the script
sweeps ``--rho``.

For LQR, the MPC at each ``--rho`` and each agent given, it prints one JSON line: the
policy's cost on the random validation loads the recipes select their runs on
(:func:`train.core.evaluate.validation_cost`: the env's reward per load scaled by the
passive beam's, so passive 1 and lower is better; ``--loads``, default the recipes' 256)
and its ISE / LQR on cases 1, 2, 3 and the held-out random loads
(:func:`train.core.evaluate.ise_rel_lqr`). Not a test, and not an agent; about 30 s per
MPC on 256 loads::

    python studies/probes/objective_headroom.py --agents train/agents/vrs train/agents/ppo

Its numbers are in docs/training.md ("Reinforcement learning from scratch", "What the
objective leaves beyond a linear law").
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import gymnasium as gym

from baselines.policies import LQRPolicy, MPCPolicy
from train.agent import TrainedAgent
from train.core.evaluate import (
    CASES,
    DEFAULT_ENV_ID,
    eval_episodes,
    lqr_ise,
    relative_ise,
    rollout_ise,
    validation_cost,
    validation_seeds,
)

#: The MPC's horizon [steps of 1 ms]: MPCPolicy's default; 150 steps do not lower the best
#: validation cost of the sweep (docs/training.md).
HORIZON = 60
#: The voltage weights swept by default: the env's lam (0.01), about the best of the sweep in
#: docs/training.md (0.004) and below it.
RHOS = (0.01, 0.004, 0.001)


def mpc(env, rho: float, horizon: int = HORIZON) -> MPCPolicy:
    """The certainty-equivalent MPC of the env's reward with voltage weight ``rho`` (module
    docstring): :class:`MPCPolicy` with ``state_weight=0`` on ``env``'s nominal model."""
    return MPCPolicy.for_env(env, horizon=horizon, rho=rho, state_weight=0.0)


def row(name: str, policy, env_id: str, seeds, episodes: dict, refs: dict) -> dict:
    """The JSON line of ``policy``: its validation cost on the loads of ``seeds`` and its ISE
    per case on ``episodes`` relative to ``refs`` (``{"lqr": LQR's ISE per case}``, both
    computed once for all rows), with the seconds both took; the ISE as
    :func:`train.core.evaluate.ise_rel_lqr` has it."""
    t0 = time.perf_counter()
    cost = validation_cost(policy, env_id, seeds)
    rel = relative_ise(rollout_ise(policy, env_id, episodes), refs)
    return {
        "policy": name,
        "validation_cost": cost,
        "ise_rel_lqr": [rel[c] for c in CASES],
        "seconds": round(time.perf_counter() - t0, 1),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--agents", type=Path, nargs="*", default=[], help="agent directories")
    ap.add_argument(
        "--rho", type=float, nargs="+", default=list(RHOS), help="the MPC's voltage weights"
    )
    ap.add_argument("--horizon", type=int, default=HORIZON, help="the MPC's horizon [steps]")
    ap.add_argument("--loads", type=int, default=256, help="validation loads (default 256)")
    ap.add_argument("--env-id", default=DEFAULT_ENV_ID, help="env id of the LQR and the MPC")
    args = ap.parse_args(argv)
    if args.loads < 1:
        ap.error(f"--loads: expected a positive number of loads, got {args.loads}")
    if any(not r >= 0 for r in args.rho):
        ap.error(f"--rho: expected non-negative weights, got {args.rho}")
    if args.horizon < 1:
        ap.error(f"--horizon: expected a positive number of steps, got {args.horizon}")
    agents = [TrainedAgent.load(d, name=d.name) for d in args.agents]
    for ag in agents:
        if ag.metadata["env"]["id"] != args.env_id:
            ap.error(
                f"--agents: {ag.name!r} was trained on {ag.metadata['env']['id']!r}, "
                f"not --env-id {args.env_id!r}"
            )
    env = gym.make(args.env_id)  # the policies are designed on its nominal model
    seeds = validation_seeds(args.loads)
    policies = {"lqr": LQRPolicy.for_env(env)}
    policies |= {f"mpc rho={r:g}": mpc(env, r, args.horizon) for r in args.rho}
    policies |= {ag.name: ag for ag in agents}
    episodes = eval_episodes()
    refs = {"lqr": lqr_ise(args.env_id, episodes)}
    for name, policy in policies.items():
        print(json.dumps(row(name, policy, args.env_id, seeds, episodes, refs)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
