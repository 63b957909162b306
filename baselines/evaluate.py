"""Evaluate every reference of a level on the thesis's three load cases in ``ACLDBeam-v1`` (or
any registered id), and score them.

``python -m baselines.evaluate [--env-id ID] [--mesh converged|thesis] [--json PATH]
[--plots DIR] [--score-episodes N]`` prints a table per case (peak [mm], 5 % settling [s],
ISE [m^2 s] and relative to the thesis LQR and to the bound, max |V| [V], return) and each
policy's effort (RMS voltage, amplifier reactive power, chattering and time at the limit
after the tip has settled: :mod:`baselines.analysis.effort`) for the level's references
(:mod:`baselines.marks`): the passive beam; the thesis's LQR and SMC and the nominal MPC,
delay-free designs on the nominal model; the engineer's designs for the level's known
actuator (:mod:`baselines.engineer`); the plant oracle ``mpc_oracle``, which knows the
episode's plant and actuator but not the load (:mod:`baselines.oracle`); and the
clairvoyant bound, with the env's actuator inside -- all with the +/-120 V limit and 1 ms
control, in the configuration of ``--env-id`` (default ``ACLDBeam-v1``; ``--mesh``
replaces its mesh). Then it prints score v2 of each on the env's published test set
(:mod:`baselines.evaluation.score`: passive 0, bound 1; :data:`acld_gym.test_sets.TEST_SETS`;
``--score-episodes``) beside the mean ISE relative to the thesis LQR's; on the thesis mesh
also the saturated LQR/SMC rows against thesis Table 2. The id and the output paths are
checked before anything is computed. Any object with SB3's ``predict`` can be evaluated
with :func:`rollout` (:mod:`baselines.rollout`, re-exported here), so trained agents use
the same code; a policy that records an ``observation_fingerprint`` is checked against the
env's before it acts.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from acld_gym import ENV_ID
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.presets import check_env_id, preset
from acld_gym.physics.loads import THESIS_CASES
from acld_gym.physics.truth import MESHES
from acld_gym.test_sets import TEST_SETS
from acld_gym.thesis.table2 import thesis_row
from acld_gym.util.atomic import check_directory, check_writable, save_figure, write_json
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type

from .analysis.effort import settled_from
from .analysis.score import format_scores, score_policies
from .cases import episode_rows, evaluate, mean_rows
from .marks import level_references, mark_labels
from .policies import MPC_MISSING, default_policies, policies_for, policy_classes
from .rollout import (  # the primitives, re-exported: their home is baselines.rollout
    Episode,
    EvalRow,
    bound_episode,
    check_compatible,
    metrics_row,
    rollout,
)

__all__ = [
    "EvalRow",
    "Episode",
    "rollout",
    "check_compatible",
    "bound_episode",
    "episode_rows",
    "evaluate",
    "policy_classes",
    "default_policies",
    "policies_for",
    "level_references",
    "metrics_row",
    "mean_rows",
    "format_legend",
    "format_tables",
    "format_effort",
    "format_thesis_comparison",
    "add_scores",
    "add_score_episodes_argument",
    "check_score_episodes",
    "plot_episodes",
]


def format_legend(labels: dict) -> str:
    """One line: the policies of each kind (:func:`baselines.marks.mark_labels`)."""
    kinds: dict[str, list[str]] = {}
    for name, kind in labels.items():
        kinds.setdefault(kind, []).append(name)
    return "policies: " + "; ".join(f"{', '.join(n)} = {k}" for k, n in kinds.items())


def format_tables(rows: list[EvalRow]) -> str:
    out = []
    for case in dict.fromkeys(r.case for r in rows):
        sub = [r for r in rows if r.case == case]
        bound = next((r.ise for r in sub if r.policy == "bound"), None)
        lqr = next((r.ise for r in sub if r.policy == "lqr"), None)
        out.append(f"\nload case {case}")
        out.append(
            f"{'policy':>10} {'peak [mm]':>10} {'settle [s]':>10} {'ISE [m^2 s]':>12} "
            f"{'/LQR':>6} {'/bound':>7} {'max|V|':>7} {'return':>10} {'ms/step':>8}"
        )
        for r in sub:
            rel_l = f"{r.ise / lqr:6.2f}" if lqr else "     -"
            rel_b = f"{r.ise / bound:7.2f}" if bound else "      -"
            out.append(
                f"{r.policy:>10} {r.peak_mm:10.3f} {r.settling_s:10.3f} {r.ise:12.3e} "
                f"{rel_l} {rel_b} {r.max_voltage_V:7.1f} {r.ret:10.1f} "
                f"{r.ms_per_step:8.3f}"
            )
        out.extend(format_effort(sub))
    return "\n".join(out)


def format_effort(rows: list[EvalRow]) -> list[str]:
    """The effort lines of one case's rows (:mod:`baselines.analysis.effort`)."""

    def num(x: float, width: int, prec: int, scale: float = 1.0) -> str:
        return f"{x * scale:{width}.{prec}f}" if math.isfinite(x) else "-".rjust(width)

    start = settled_from(rows[0].case)
    when = f"after {start:.3f} s:" if math.isfinite(start) else "(no settled window)"
    out = [
        f"{'effort':>10} {'V rms [V]':>10} {'Q [mvar]':>9}  {when:>19} {'TV [kV/s]':>9} "
        f"{'at limit':>8} {'tip rms [um]':>12}"
    ]
    for r in rows:
        out.append(
            f"{r.policy:>10} {r.rms_voltage_V:10.1f} {num(r.reactive_power_var, 9, 2, 1e3)}"
            f"  {'':>19} {num(r.total_variation_V_per_s, 9, 2, 1e-3)} "
            f"{num(r.limit_fraction, 7, 1, 100)}% "
            f"{num(r.residual_tip_rms_m, 12, 2, 1e6)}"
        )
    return out


def format_thesis_comparison(rows: list[EvalRow]) -> str:
    """The env's saturated LQR and SMC rows against thesis Table 2 (peak, settling): the
    acceptance check of the reference policies on the thesis mesh (7 % peak, 10 %
    settling; tests/baselines/test_policies.py)."""
    out = [
        "\nagainst thesis Table 2 (saturated rows; acceptance: peak 7 %, settling 10 %)",
        f"{'row':>12} {'peak':>8} {'settling':>9}",
    ]
    for r in rows:
        ref = thesis_row(r.case, r.policy, True) if r.case in THESIS_CASES else None
        if ref is not None:
            out.append(
                f"{r.policy.upper() + ' case ' + str(r.case):>12} "
                f"{100 * (r.peak_mm / ref.peak_mm - 1):+7.1f}% "
                f"{100 * (r.settling_s / ref.settling_s - 1):+8.1f}%"
            )
    return "\n".join(out)


def add_score_episodes_argument(p: argparse.ArgumentParser) -> None:
    """The ``--score-episodes N`` option of the CLIs that score policies on a test set
    (``baselines.evaluate``, ``baselines.analyze``, ``train.compare``); checked against the
    set's size by :func:`check_score_episodes`."""
    p.add_argument(
        "--score-episodes",
        type=arg_type(int, 0, 100_000),
        default=None,
        help="score on the first N episodes of the test set (0: no score; default: all of it)",
    )


def check_score_episodes(n_episodes: int | None, env_id: str = ENV_ID) -> None:
    """``ValueError`` naming ``--score-episodes`` unless ``n_episodes`` (None: the whole
    set) fits the test set of ``env_id``: a CLI checks it before any computing."""
    size = len(TEST_SETS[env_id].seeds)
    if n_episodes is not None and n_episodes > size:
        raise ValueError(
            f"--score-episodes: the test set of {env_id} has {size} episodes, got {n_episodes}"
        )


def add_scores(
    policies: dict,
    n_episodes: int | None,
    env_kwargs: dict,
    quiet: bool = True,
    labels: dict | None = None,
    env_id: str = ENV_ID,
) -> dict:
    """Score ``policies`` on the test set of ``env_id`` (the first ``n_episodes``; 0:
    none), print the score table, and return ``{policy: score dict}`` for the JSON rows."""
    if n_episodes == 0:
        return {}
    scores = score_policies(
        policies, env_id=env_id, n_episodes=n_episodes, env_kwargs=env_kwargs, quiet=quiet
    )
    where = ", ".join(
        f"{k}={v!r}" for k, v in env_kwargs.items() if v and (k, v) != ("mesh", "converged")
    )
    text = format_scores(scores, labels)
    print(text.replace(" random loads", f" random loads, {where}", 1) if where else text)
    return {name: s.as_dict() for name, s in scores.items()}


def plot_episodes(episodes: dict, directory: Path) -> None:
    """One figure per case of ``episodes`` ((case, name) -> Episode) in ``directory``."""
    import matplotlib  # heavy to import (~0.3 s): only --plots draws

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # (the same)

    directory.mkdir(parents=True, exist_ok=True)
    for case in dict.fromkeys(c for c, _ in episodes):
        fig, ax = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
        for (c, name), ep in episodes.items():
            if c != case:
                continue
            ax[0].plot(ep.t, ep.y * 1e3, lw=0.8, label=name)
            ax[1].plot(ep.t, ep.voltage, lw=0.8, label=name)
        ax[0].set_ylabel("tip deflection [mm]")
        ax[1].set_ylabel("voltage [V]")
        ax[1].set_xlabel("time [s]")
        ax[0].set_title(f"Load case {case}: all policies, +/-120 V, 1 ms, Kalman observer")
        ax[0].legend(ncol=5, fontsize=8)
        for a in ax:
            a.grid(alpha=0.3)
        fig.tight_layout()
        save_figure(fig, directory / f"policies_case{case}.png", dpi=110)
        plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog=prog("python -m baselines.evaluate"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--json", metavar="PATH", help="write the rows as JSON")
    p.add_argument("--plots", metavar="DIR", help="write one figure per case to DIR")
    p.add_argument(
        "--seed", type=arg_type(int, 0, 2**63 - 1), default=0, help="episode seed (sensor noise)"
    )
    p.add_argument(
        "--env-id", default=ENV_ID, help=f"a registered id of this package (default {ENV_ID})"
    )
    p.add_argument(
        "--mesh",
        choices=MESHES,
        default=None,
        help="truth plant: the mesh-converged beam or the thesis mesh (default: "
        "the configuration's)",
    )
    add_score_episodes_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress line")
    args = p.parse_args(argv)
    try:  # a bad id, unusable output paths and a bad --score-episodes fail now, before
        check_env_id(args.env_id, "--env-id")  # any computing
        if args.json:
            check_writable(args.json, "--json")
        if args.plots:
            check_directory(args.plots, "--plots")
        check_score_episodes(args.score_episodes, args.env_id)
        try:
            config = preset(args.env_id, **({} if args.mesh is None else {"mesh": args.mesh}))
        except ValueError as exc:  # a preset's settings made for another mesh
            raise ValueError(f"--mesh {args.mesh}: {exc}") from None
    except ValueError as exc:
        p.error(str(exc))
    probe = ACLDBeamEnv(config=config)  # build the design once before timing anything
    episodes: dict = {}
    policies = level_references(probe)
    if "mpc" not in policies:
        print(f"mpc skipped (and mpc_rig, mpc_oracle): {MPC_MISSING}")
    labels = mark_labels(policies)
    rows = evaluate(
        policies, seed=args.seed, env_kwargs={"config": config}, episodes=episodes, quiet=args.quiet
    )
    print(format_legend(labels))
    print(format_tables(rows))
    if config.mesh == "thesis":
        print(format_thesis_comparison(rows))
    mesh = {} if args.mesh is None else {"mesh": args.mesh}  # (every id has a test set)
    # (the kinds are the legend's: a column of words would split the table's numbers)
    scores = add_scores(policies, args.score_episodes, mesh, args.quiet, env_id=args.env_id)
    if args.json:
        write_json(
            args.json,
            [
                dict(r.as_dict(), kind=labels.get(r.policy), score=scores.get(r.policy))
                for r in rows
            ],
        )
        print(f"\nwrote {args.json}")
    if args.plots:
        plot_episodes(episodes, Path(args.plots))
        print(f"wrote figures to {args.plots}/")
    return 0


if __name__ == "__main__":
    from acld_gym.util.validate import run_main

    sys.exit(run_main(main))
