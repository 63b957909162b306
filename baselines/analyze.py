"""Read a policy in control terms and score it between the passive beam and the clairvoyant
bound.

``python -m baselines.analyze POLICY [POLICY ...]`` (options: ``--help``);
``python -m train.analyze`` is the same command for agent directories too.

POLICY is a reference of the level (:mod:`baselines.marks`: ``passive``; the thesis's
delay-free ``lqr`` and ``smc`` and the nominal ``mpc``; the engineer's designs for the
level's actuator, ``lqg`` and ``mpc_rig`` (:mod:`baselines.engineer`); the plant oracle
``mpc_oracle`` (:mod:`baselines.oracle`)), ``references`` for all of them, or an agent
directory, read by the ``load_agent`` a caller passes to :func:`main` (``python -m
train.analyze``, the same command with train's agent loader). Through the env it
measures the closed-loop modes 1-3 (frequency, damping ratio) from a small tip pulse, the
drop of each mode's load-to-tip compliance peak against the passive beam (multisine),
for a policy linear about rest the exact closed-loop modes of the sampled loop and the
gain and phase margins at the actuator, the effort on the thesis cases (RMS voltage,
amplifier reactive power, chattering and time at the limit after settling), and score v2
on the env's published test set: the interquartile mean over its episodes of
(ISE_passive - ISE) / (ISE_passive - ISE_bound) with a 95 % bootstrap interval (the bound
1), beside the mean ISE relative to the thesis LQR's. The same in Python:
:func:`baselines.analysis.control.analyze` (re-exported here as :func:`analyze`). The id
and the output paths are checked before anything is computed.

With one POLICY, ``--json`` writes its record; with several, a list of records, and
``--markdown`` the comparison tables; ``--plots`` writes ``compliance_<policy>.png`` each.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import gymnasium as gym

import acld_gym
from acld_gym.envs.presets import check_env_id
from acld_gym.test_sets import TEST_SETS
from acld_gym.util.atomic import strict_json, write_json, write_text
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import run_main

from .analysis.control import Analysis, analyze
from .analysis.references import references
from .analysis.report import format_analysis, markdown_summary, plot_compliance
from .arguments import outputs
from .evaluate import add_score_episodes_argument, check_score_episodes
from .marks import level_references

__all__ = [
    "analyze",
    "Analysis",
    "BASELINES",
    "ALL",
    "AgentLoader",
    "refuse_agent_directory",
    "resolve_policy",
    "resolve_policies",
    "main",
]

#: The references of every level by name (:func:`baselines.marks.level_references`; where
#: the QP solver osqp is missing, a level has no ``mpc``, ``mpc_rig`` or ``mpc_oracle``).
BASELINES = ("passive", "lqr", "smc", "mpc", "lqg", "mpc_rig", "mpc_oracle")
#: The POLICY that stands for all of the level's references.
ALL = "references"
#: What reads an agent directory into a policy (anything with ``predict``, the package's
#: policy interface): ``load_agent(path)``.
AgentLoader = Callable[[Path], object]


def refuse_agent_directory(path: Path):
    """The default ``load_agent`` of :func:`main` and :func:`resolve_policies`: it refuses an
    agent directory in one line. The agent folder's format is train's, the layer above, so
    this command reads an agent through ``python -m train.analyze`` (``acld-gym analyze``),
    which passes train's loader; baselines imports nothing from train."""
    raise ValueError(
        f"POLICY: {path.name!r} is an agent directory: analyze it with "
        f"`python -m train.analyze {path}` (acld-gym analyze), which reads the agent format"
    )


def resolve_policies(
    spec: str,
    env_id: str,
    env_kwargs: dict | None = None,
    load_agent: AgentLoader | None = None,
) -> list:
    """``[(policy, name), ...]`` for a reference's name, :data:`ALL` or an agent
    directory (read by ``load_agent``; without one it is refused:
    :func:`refuse_agent_directory`); ``ValueError`` naming ``POLICY`` otherwise."""
    if spec in BASELINES or spec == ALL:
        refs = level_references(gym.make(env_id, **(env_kwargs or {})))
        if spec == ALL:
            return [(pol, name) for name, pol in refs.items()]
        if spec not in refs:
            raise ValueError(f"POLICY: {spec!r} is not available here (osqp is not installed)")
        return [(refs[spec], spec)]
    path = Path(spec)
    if not path.is_dir():
        raise ValueError(
            f"POLICY: expected one of {[*BASELINES, ALL]} or an agent directory, got {spec!r}"
        )
    return [((load_agent or refuse_agent_directory)(path), path.name)]


def resolve_policy(
    spec: str,
    env_id: str,
    env_kwargs: dict | None = None,
    load_agent: AgentLoader | None = None,
):
    """``(policy, name)`` for a reference's name or an agent directory (not :data:`ALL`);
    ``ValueError`` naming ``POLICY`` otherwise."""
    if spec == ALL:
        raise ValueError(f"POLICY: {ALL!r} stands for several policies")
    return resolve_policies(spec, env_id, env_kwargs, load_agent)[0]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog("python -m baselines.analyze"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "policy",
        metavar="POLICY",
        nargs="+",
        help=f"one of {', '.join(BASELINES)}, {ALL} (all of them), or an agent directory",
    )
    p.add_argument(
        "--env-id",
        default=acld_gym.ENV_ID,
        help=f"a registered id of this package with a test set (default {acld_gym.ENV_ID})",
    )
    p.add_argument("--json", metavar="PATH", help="write the record as JSON")
    p.add_argument("--plots", metavar="DIR", help="write the compliance figures to DIR")
    p.add_argument("--markdown", metavar="PATH", help="write the comparison tables as markdown")
    add_score_episodes_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress line")
    return p


def main(argv: list[str] | None = None, load_agent: AgentLoader | None = None) -> int:
    """The command: ``argv`` as on the command line; an agent directory among the POLICY
    arguments is read by ``load_agent`` (without one, refused: :func:`refuse_agent_directory`;
    ``python -m train.analyze`` passes train's)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:  # a bad id, unusable output paths and a bad POLICY fail now, before any computing
        check_env_id(args.env_id, "--env-id")
        if args.env_id not in TEST_SETS:
            raise ValueError(f"--env-id: no published test set for {args.env_id!r}")
        outputs({"--json": args.json, "--markdown": args.markdown}, {"--plots": args.plots})
        check_score_episodes(args.score_episodes, args.env_id)
        policies = [
            p for spec in args.policy for p in resolve_policies(spec, args.env_id, None, load_agent)
        ]
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    refs = None
    if args.score_episodes != 0:
        test = TEST_SETS[args.env_id]
        refs = references(
            test if args.score_episodes is None else test.first(args.score_episodes),
            quiet=args.quiet,
        )
    results = []
    for policy, name in policies:
        result = analyze(
            policy,
            args.env_id,
            name=name,
            score_episodes=args.score_episodes,
            refs=refs,
            quiet=args.quiet,
        )
        print(format_analysis(result) + "\n")
        if args.plots:
            print(f"wrote {plot_compliance(result, Path(args.plots) / f'compliance_{name}.png')}")
        results.append(result)
    if args.json:
        records = [strict_json(r.as_dict()) for r in results]
        write_json(args.json, records[0] if len(records) == 1 else records)
        print(f"wrote {args.json}")
    if args.markdown:
        write_text(args.markdown, markdown_summary(results) + "\n")
        print(f"wrote {args.markdown}")
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
