"""Where a recipe's runs end: the mean of its seeds' linear laws, evaluated.

The PPO recipe and the random search both return a saturated linear law on the raw
observation, :math:`a = \\mathrm{clip}(z W + b, -1, 1)`. Their seeds end at different
points of a flat valley of near-optimal laws and differ on the thesis's single loads
(case 1: 0.83-0.93 x LQR per seed) more than on the objective. The mean of k seeds' laws,
:math:`(\\bar W, \\bar b)`, estimates the valley's point the recipe ends at on average; where
the cost is convex near the laws, it is at least as good as the k laws' mean cost. This
script evaluates, for each of the n agents of benchmarks' output directories in seed order,
the mean law of it and its k - 1 successors (cyclically), and prints the IQM over the n
groups next to the single agents' IQM (ISE / LQR on cases 1 / 2 / 3 / random on the env
the agents were trained on, the benchmark's evaluation:
:func:`train.core.evaluate.batched_ise`). Not a test, and not a training recipe: an
analysis of runs already made; a few seconds::

    python studies/probes/law_average.py DIR [DIR ...] [--algo ppo] --k 10

Its numbers are in docs/training.md ("Reinforcement learning from scratch", "Case 1 does
not follow the objective").
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from acld_gym.util.stats import iqm
from train.agent import ActorProgram, TrainedAgent
from train.core.evaluate import CASES, batched_ise, eval_episodes, lqr_ise, relative_ise

#: The actor program of a saturated linear law (:func:`train.agent.linear_program`; an
#: exported SB3 actor has the first operation only: the program clips its output anyway).
LINEAR_OPS = ({"op": "linear", "layer": 0}, {"op": "clip", "low": -1.0, "high": 1.0})
#: The metadata that must agree for two laws to act on the same observation alike.
SAME = ("env", "observation", "residual", "action_headroom")


def mean_law(agents: list[TrainedAgent]) -> TrainedAgent:
    """The agent whose law is the mean of ``agents``' saturated linear laws: W0 and b0
    averaged, the first agent's metadata. Each must be a saturated linear law
    (:data:`LINEAR_OPS`) with the first's ``SAME`` metadata; otherwise ValueError names it."""
    if not agents:
        raise ValueError("agents must hold at least one agent, got none")
    first = agents[0]
    for ag in agents:
        if [dict(op) for op in ag.actor.ops] not in (list(LINEAR_OPS), list(LINEAR_OPS[:1])):
            raise ValueError(
                f"agents: {ag.name!r} is not a saturated linear law (its actor: {ag.actor.ops})"
            )
        for key in SAME:
            if ag.metadata.get(key) != first.metadata.get(key):
                raise ValueError(
                    f"agents: {ag.name!r} differs from {first.name!r} in {key!r}; "
                    "their laws act on different observations or voltages"
                )
    arrays = {k: np.mean([ag.actor.arrays[k] for ag in agents], axis=0) for k in ("W0", "b0")}
    return TrainedAgent(ActorProgram(list(LINEAR_OPS), arrays), first.metadata, "mean law")


def cyclic_groups(n: int, k: int) -> list[tuple[int, ...]]:
    """For each i < n the k indices i, i + 1, ..., i + k - 1 modulo n (1 <= k <= n)."""
    if not 1 <= k <= n:
        raise ValueError(f"k must be between 1 and the number of agents {n}, got {k}")
    return [tuple((i + j) % n for j in range(k)) for i in range(n)]


def load_agents(directories: list[Path], algo: str | None = None) -> list[TrainedAgent]:
    """The agents of benchmarks' output ``directories`` (``agents/<algo>-s<seed>``) of one
    ``algo`` (None: the only one there), in seed order."""
    dirs = []
    for directory in directories:
        found = list((directory / "agents").glob(f"{algo or '*'}-s*"))
        if not found:
            raise FileNotFoundError(
                f"directories: {str(directory)!r} has no agents/{algo or '<algo>'}-s<seed> "
                "directories"
            )
        dirs += found
    algos = sorted({d.name.rsplit("-s", 1)[0] for d in dirs})
    if len(algos) > 1:
        raise ValueError(f"directories hold agents of {algos}; choose one with algo (--algo)")
    dirs.sort(key=lambda d: int(d.name.rsplit("-s", 1)[1]))
    return [TrainedAgent.load(d, name=d.name) for d in dirs]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "directories", type=Path, nargs="+", help="benchmarks' output directories (--out)"
    )
    ap.add_argument("--algo", help="the agents' algorithm (default: the only one there)")
    ap.add_argument("--k", type=int, default=1, help="laws per mean (default 1: each alone)")
    args = ap.parse_args(argv)
    agents = load_agents(args.directories, args.algo)
    groups = cyclic_groups(len(agents), args.k)
    env_id = agents[0].metadata["env"]["id"]  # the one env of all (mean_law checks "env")
    episodes = eval_episodes()
    refs = {"lqr": lqr_ise(env_id, episodes)}

    def rel(agent) -> list[float]:
        ise = relative_ise(batched_ise(agent, env_id, episodes), refs)
        return [ise[c] for c in CASES]

    single = [rel(ag) for ag in agents]
    # k = 1: each group is one agent, whose mean law is its own (evaluated once)
    means = single if args.k == 1 else [rel(mean_law([agents[i] for i in g])) for g in groups]
    for g, r in zip(groups, means, strict=True):
        print(json.dumps({"laws": [agents[i].name for i in g], "ise_rel_lqr": r}))
    for label, rows in (("single", single), (f"mean of {args.k}", means)):
        print(label, "IQM", " / ".join(f"{iqm([r[j] for r in rows]):.4f}" for j in range(4)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
