"""``python -m train.compare``: the agents of a folder against the reference policies of
their level.

The level is one of this package's env ids: ``--env-id ID``, or else the level every agent
of ``--agents`` (default: the shipped ``train/agents``) was trained on, as its metadata
records it; the first line of the output names it. Agents of different levels are refused
in one line, as an agent of another level than ``--env-id``, before anything is computed.

For each thesis load case (1, 2, 3) and a fixed held-out set of random loads (``case
"random"``: the mean over the set; seeds disjoint from training), runs the level's
references (the thesis's delay-free LQR and SMC, the nominal MPC, ``mpc_reward``, the
engineer's designs for the level's actuator and sensor, the plant oracle ``mpc_oracle``:
the same marks on every level), every agent (labelled by how it was trained) and
the bound through the level's env; prints peak [mm], 5 % settling [s], ISE [m^2 s] (and /
LQR, / bound), max |V| [V], return, ms per step, the effort after settling
(:mod:`baselines.analysis.effort`), and score v2 on the level's test set
(:mod:`baselines.evaluation.score`: passive 0, bound 1; ``--score-episodes``) beside the
mean ISE relative to the thesis LQR's.

``--mesh`` and ``--param-noise X`` change the level's truth plant and its per-episode
parameter randomization (the same plants for every policy; the bound knows the plant).
``--json PATH``: the rows (``baselines.evaluate``'s, plus ``ise_rel_lqr``,
``ise_rel_bound``, ``score``, ``env_id``); ``--markdown PATH``: the table and the score
table; ``--plots DIR``: a figure per thesis case and the learning curves.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from acld_gym import ENV_ID
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.presets import PRESETS, check_env_id
from acld_gym.physics.truth import MESHES
from acld_gym.util.atomic import write_json, write_text
from acld_gym.util.progress import Progress
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type, run_main
from baselines.arguments import folder_name, input_directory, outputs
from baselines.evaluate import (
    EvalRow,
    add_score_episodes_argument,
    add_scores,
    check_score_episodes,
    episode_rows,
    format_tables,
    mean_rows,
    plot_episodes,
)
from baselines.evaluation.score import SCORE_NAME
from baselines.marks import marks_for
from baselines.policies import RewardMPCPolicy, mpc_available, policies_for

from .agent_dirs import AGENTS_DIR, agent_names, load_agents
from .compare_level import check_agents_fit, level_config, resolve_level
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


def reference_policies(mesh: str | None = None, env_id: str = ENV_ID) -> dict:
    """The references of the level ``env_id`` (``mesh``: its truth plant; None: the
    level's), as :func:`baselines.marks.level_references` gives them, with the MPC of the
    env's reward: passive, LQR, SMC, MPC (:func:`baselines.policies.policies_for`) and,
    with osqp, ``"mpc_reward"`` (:class:`baselines.policies.RewardMPCPolicy`) on the
    level's nominal model; the engineer's designs and the plant oracle
    (:func:`baselines.marks.marks_for`)."""
    probe = ACLDBeamEnv(config=level_config(env_id, mesh))
    out = policies_for(probe)
    if mpc_available():
        out[RewardMPCPolicy.name] = RewardMPCPolicy.for_env(probe)
    return out | marks_for(probe)


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
        "--env-id",
        metavar="ID",
        default=None,
        help=f"the level to compare on, one of {', '.join(PRESETS)}; every agent must have "
        "been trained on it (default: the level the agents were trained on)",
    )
    p.add_argument(
        "--only",
        metavar="NAME",
        nargs="*",
        default=(),
        help="these agents only (default: every agent of --agents trained on the mesh)",
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
        default=None,
        help="per-episode parameter randomization of the plant (default: the level's, 0 "
        "except on ACLDBeamHard-v1)",
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
        default=None,
        help="truth plant (default: the level's, the converged beam except on ACLDBeam-v0); "
        "the agents trained on it",
    )
    add_score_episodes_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress line")
    return p


def main(argv: list[str] | None = None) -> int:
    """The command; the level is settled first (:mod:`train.compare_level`)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:  # every argument and every agent's level are checked now, before any computing
        outputs({"--json": args.json, "--markdown": args.markdown}, {"--plots": args.plots})
        if args.env_id is not None:  # a plain string, never handed to an importer
            check_env_id(args.env_id, "--env-id")
        input_directory(args.agents, "--agents")
        for name in args.only:
            folder_name(name, "--only")
        level = resolve_level(args.agents, args.only, args.env_id, args.mesh)
        config = level_config(level.env_id, args.mesh, args.param_noise)
        check_score_episodes(args.score_episodes, level.env_id)
        if not level.names:
            raise ValueError(
                f"--agents: no agent trained on --mesh {config.mesh} in {args.agents!r}"
            )
        agents = load_agents(args.agents, list(level.names))
        check_agents_fit(agents, ACLDBeamEnv(config=config))
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    print(level.first_line(), flush=True)
    env_id = level.env_id
    policies = {**reference_policies(config.mesh, env_id), **agents}
    seeds = tuple(range(HELDOUT_SEEDS[0], HELDOUT_SEEDS[0] + args.random_episodes))
    episodes: dict = {}
    rows = compare(
        policies,
        random_seeds=seeds,
        seed=args.seed,
        env_kwargs={"config": config},
        episodes=episodes,
        quiet=args.quiet,
    )
    labels = training_labels(policies)
    noise = f", param_noise = {config.param_noise}" if config.param_noise else ""
    title = (
        f"Agents vs reference policies on {env_id}{noise}; 'random' = mean over {len(seeds)} "
        "held-out random-load episodes"
    )
    print(title)
    print(format_tables(rows))
    base = level_config(env_id)  # the test set's env: the level, with what the user changed
    changed = {k: getattr(config, k) for k in ("mesh", "param_noise")}
    changed = {k: v for k, v in changed.items() if v != getattr(base, k)}
    scores = add_scores(policies, args.score_episodes, changed, args.quiet, labels, env_id)
    table = [dict(d, score=scores.get(d["policy"]), env_id=env_id) for d in relative(rows, labels)]
    if args.json:
        write_json(args.json, table)
        print(f"\nwrote {args.json}")
    if args.markdown:
        scored = markdown_scores(table)
        write_text(
            args.markdown,
            f"{title}.\n\n{markdown_table(table)}\n" + (f"\n{scored}\n" if scored else ""),
        )
        print(f"wrote {args.markdown}")
    if args.plots:
        plot_episodes(episodes, Path(args.plots))
        plot_learning_curves(agents, Path(args.plots))
        print(f"wrote figures to {args.plots}/")
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
