"""``python -m train.compare``: the shipped agents against the reference policies.

For each thesis load case (1, 2, 3) and a fixed held-out set of random loads (``case
"random"``: the mean over the set; seeds disjoint from training), runs the references
(:func:`reference_policies`: the thesis's delay-free LQR and SMC, the nominal MPC,
``mpc_reward``, the engineer's designs, the plant oracle ``mpc_oracle``), every shipped
agent (labelled by how it was trained) and the bound through ``ACLDBeam-v1``; prints peak
[mm], 5 % settling [s], ISE [m^2 s] (and / LQR, / bound), max |V| [V], return, ms per
step, the effort after settling (:mod:`baselines.analysis.effort`), and score v2 on the
test set (:mod:`baselines.evaluation.score`: passive 0, bound 1; ``--score-episodes``)
beside the mean ISE relative to the thesis LQR's.

``--param-noise X``: per-episode parameter randomization (the same plants for every
policy; the bound knows the plant). ``--json PATH``: the rows (``baselines.evaluate``'s,
plus ``ise_rel_lqr``, ``ise_rel_bound``, ``score``); ``--markdown PATH``: the table and
the score table; ``--plots DIR``: a figure per thesis case and the learning curves.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.physics.truth import MESHES
from acld_gym.util.atomic import write_json, write_text
from acld_gym.util.progress import Progress
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type, run_main
from baselines.arguments import folder_name, input_directory, outputs, param_noise
from baselines.evaluate import (
    EvalRow,
    add_score_episodes_argument,
    add_scores,
    check_score_episodes,
    default_policies,
    episode_rows,
    format_tables,
    mean_rows,
    plot_episodes,
)
from baselines.evaluation.score import SCORE_NAME
from baselines.marks import marks_for
from baselines.policies import RewardMPCPolicy, mpc_available

from .agent_dirs import AGENTS_DIR, agent_names, load_agents
from .core.evaluate import HELDOUT_SEEDS  # re-exported (defined with the other eval seeds)
from .curves_figure import learning_curves_figure, plot_learning_curves

__all__ = [
    "AGENTS_DIR",
    "HELDOUT_SEEDS",
    "agent_names",
    "load_agents",
    "training_labels",
    "reference_policies",
    "compare",
    "relative",
    "markdown_table",
    "markdown_scores",
    "learning_curves_figure",
    "plot_learning_curves",
    "main",
]


def reference_policies(mesh: str = "converged") -> dict:
    """Passive, LQR, SMC, MPC (:func:`baselines.evaluate.default_policies`) and, with osqp,
    the MPC of the env's reward (``"mpc_reward"``, :class:`baselines.policies.
    RewardMPCPolicy`) on the nominal ``mesh`` plant; the engineer's designs and the plant
    oracle (:func:`baselines.marks.marks_for`)."""
    out = default_policies(mesh)
    if mpc_available():
        out[RewardMPCPolicy.name] = RewardMPCPolicy(mesh=mesh)
    return out | marks_for(ACLDBeamEnv(mesh=mesh))


def training_labels(policies: dict) -> dict[str, str]:
    """How each policy came about: an agent's ``training``; "designed" for a reference,
    "oracle" for the plant oracle (:mod:`baselines.oracle`), "clairvoyant" for the bound."""
    kind = {True: "oracle", False: "designed"}
    out = {
        n: getattr(p, "training", kind[hasattr(p, "start_episode")]) for n, p in policies.items()
    }
    return out | {"bound": "clairvoyant"}


def compare(
    policies: dict,
    cases=(1, 2, 3),
    random_seeds=HELDOUT_SEEDS,
    seed: int = 0,
    env_kwargs: dict | None = None,
    episodes: dict | None = None,
    quiet: bool = True,
) -> list[EvalRow]:
    """Rows per thesis case (episode ``seed``) and the mean over the held-out random
    episodes (``case="random"``); every policy sees the same episodes. A progress line
    on a terminal unless ``quiet``."""
    stages = (len(cases) + len(random_seeds)) * (len(policies) + 1)
    with Progress(stages, "compare", quiet) as progress:
        rows = [
            r
            for case in cases
            for r in episode_rows(policies, case, seed, env_kwargs, episodes, progress)
        ]
        if random_seeds:
            n = len(random_seeds)
            held = [
                r
                for k, s in enumerate(random_seeds)
                for r in episode_rows(
                    policies,
                    "random",
                    s,
                    env_kwargs,
                    progress=progress,
                    episode=f" · episode {k + 1}/{n}",
                )
            ]
            rows += mean_rows(held, "random")
    return rows


def relative(rows: list[EvalRow], labels: dict | None = None) -> list[dict]:
    """Rows as dicts with ``ise_rel_lqr`` and ``ise_rel_bound`` (per case) and, with
    ``labels`` (:func:`training_labels`), how each policy was trained."""
    out = []
    for r in rows:
        same = {x.policy: x.ise for x in rows if x.case == r.case}
        d = r.as_dict()
        if labels is not None:
            d["training"] = labels.get(r.policy, "")
        d["ise_rel_lqr"] = r.ise / same["lqr"] if "lqr" in same else None
        d["ise_rel_bound"] = r.ise / same["bound"] if "bound" in same else None
        out.append(d)
    return out


def markdown_table(rows: list[dict]) -> str:
    """The comparison as one markdown table (rows from :func:`relative`): the ISE, the
    episode's return (the env's reward, which charges for the voltage; the mean over the
    random loads), the effort, "-" after settling where there is no settled window
    (random loads)."""

    def num(x, fmt: str, scale: float = 1.0) -> str:
        return "-" if x is None else format(x * scale, fmt)

    head = (
        "| case | policy | trained | peak [mm] | settling [s] | ISE [m^2 s] | ISE / LQR "
        "| ISE / bound | return | max abs V [V] | V rms [V] | Q [mvar] "
        "| TV after settling [kV/s] | at limit after settling | ms / step |"
    )
    out = [head, "|" + "---|" * head.count(" | ") + "---|"]
    for d in rows:
        out.append(
            f"| {d['case']} | {d['policy']} | {d.get('training', '')} "
            f"| {d['peak_mm']:.3f} | {d['settling_s']:.3f} "
            f"| {d['ise']:.3e} | {d['ise_rel_lqr']:.2f} | {d['ise_rel_bound']:.2f} "
            f"| {d['return']:.1f} | {d['max_voltage_V']:.0f} "
            f"| {num(d.get('rms_voltage_V'), '.1f')} "
            f"| {num(d.get('reactive_power_var'), '.1f', 1e3)} "
            f"| {num(d.get('total_variation_V_per_s'), '.1f', 1e-3)} "
            f"| {num(d.get('limit_fraction'), '.0%')} | {d['ms_per_step']:.3f} |"
        )
    return "\n".join(out)


def markdown_scores(rows: list[dict]) -> str:
    """The score of each policy (one row per policy, from the ``score`` of :func:`relative`'s
    rows) as a markdown table."""
    seen: dict[str, dict] = {}
    for d in rows:
        if d.get("score") is not None:
            seen.setdefault(d["policy"], d)
    if not seen:
        return ""
    first = next(iter(seen.values()))["score"]
    out = [
        f"{SCORE_NAME.capitalize()} on `{first['test_set']}` ({first['n_episodes']} random "
        "loads): IQM of (ISE_passive - ISE) / (ISE_passive - ISE_bound) per episode, 95 % "
        "bootstrap CI (passive 0, clairvoyant bound 1); mean ISE / the thesis LQR's.",
        "",
        f"| policy | trained | {SCORE_NAME} (IQM) | 95 % CI | ISE / thesis LQR |",
        "|---|---|---|---|---|",
    ]
    for name, d in seen.items():
        sc = d["score"]
        rel = "-" if sc.get("ise_rel_thesis_lqr") is None else f"{sc['ise_rel_thesis_lqr']:.3f}"
        out.append(
            f"| {name} | {d.get('training', '')} | {sc['iqm']:.3f} "
            f"| [{sc['ci_low']:.3f}, {sc['ci_high']:.3f}] | {rel} |"
        )
    return "\n".join(out)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog("python -m train.compare"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--json", metavar="PATH", help="write the rows as JSON")
    p.add_argument("--plots", metavar="DIR", help="write the figures to DIR")
    p.add_argument("--markdown", metavar="PATH", help="write the table as markdown")
    p.add_argument(
        "--agents",
        metavar="DIR",
        default=str(AGENTS_DIR),
        help="directory of agent directories (default: the shipped train/agents)",
    )
    p.add_argument(
        "--only",
        metavar="NAME",
        nargs="*",
        default=(),
        help="these agents only (default: every agent trained on --mesh)",
    )
    p.add_argument(
        "--random-episodes",
        type=arg_type(int, 0, 1000),
        default=len(HELDOUT_SEEDS),
        help="held-out random-load episodes (default 20; 0 for none)",
    )
    p.add_argument(
        "--param-noise",
        type=arg_type(float, 0.0, 0.1),
        default=0.0,
        help="per-episode parameter randomization of the plant (default 0)",
    )
    p.add_argument(
        "--seed",
        type=arg_type(int, 0, 2**63 - 1),
        default=0,
        help="seed of the thesis-case episodes",
    )
    p.add_argument(
        "--mesh",
        choices=MESHES,
        default="converged",
        help="truth plant (default: the converged beam); the agents trained on it",
    )
    add_score_episodes_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress line")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:  # every argument is checked now, before any computing
        outputs({"--json": args.json, "--markdown": args.markdown}, {"--plots": args.plots})
        input_directory(args.agents, "--agents")
        for name in args.only:
            folder_name(name, "--only")
        param_noise(args.param_noise, args.mesh)
        check_score_episodes(args.score_episodes)
    except ValueError as exc:
        parser.error(str(exc))
    try:
        names = None if not args.only else args.only
        agents = load_agents(args.agents, names, mesh=args.mesh)
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    if not agents:
        parser.error(f"--agents: no agent trained on --mesh {args.mesh} in {args.agents!r}")
    policies = {**reference_policies(args.mesh), **agents}
    seeds = tuple(range(HELDOUT_SEEDS[0], HELDOUT_SEEDS[0] + args.random_episodes))
    episodes: dict = {}
    rows = compare(
        policies,
        random_seeds=seeds,
        seed=args.seed,
        env_kwargs={"param_noise": args.param_noise, "mesh": args.mesh},
        episodes=episodes,
        quiet=args.quiet,
    )
    labels = training_labels(policies)
    title = f" (param_noise = {args.param_noise})" if args.param_noise else ""
    print(
        f"Agents vs reference policies{title}; 'random' = mean over {len(seeds)} "
        "held-out random-load episodes"
    )
    print(format_tables(rows))
    env_kwargs = {"param_noise": args.param_noise, "mesh": args.mesh}
    scores = add_scores(policies, args.score_episodes, env_kwargs, args.quiet, labels)
    table = [dict(d, score=scores.get(d["policy"])) for d in relative(rows, labels)]
    if args.json:
        write_json(args.json, table)
        print(f"\nwrote {args.json}")
    if args.markdown:
        scored = markdown_scores(table)
        write_text(
            args.markdown, markdown_table(table) + "\n" + (f"\n{scored}\n" if scored else "")
        )
        print(f"wrote {args.markdown}")
    if args.plots:
        plot_episodes(episodes, Path(args.plots))
        plot_learning_curves(agents, Path(args.plots))
        print(f"wrote figures to {args.plots}/")
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
