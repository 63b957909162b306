"""Read a policy in control terms and score it between LQR and the clairvoyant bound.

``python -m baselines.analyze POLICY [POLICY ...] [--env-id ID] --json PATH [--plots DIR]
[--markdown PATH]``

POLICY is a reference policy (``passive``, ``lqr``, ``smc``, ``mpc``, designed on the env's
nominal model) or an agent directory (``train.agent.TrainedAgent``). Through the env it
measures the closed-loop modes 1-3 (frequency, damping ratio) from a small tip pulse, the
drop of each mode's load-to-tip compliance peak against the passive beam (multisine),
for a policy linear about rest the exact closed-loop modes of the sampled loop and the
gain and phase margins at the actuator, the effort on the thesis cases (RMS voltage,
amplifier reactive power, chattering and time at the limit after settling), and the score
on the env's published test set: the interquartile mean over its episodes of
(ISE_LQR - ISE) / (ISE_LQR - ISE_bound) with a 95 % bootstrap interval. The same in Python:
:func:`baselines.analysis.control.analyze` (re-exported here as :func:`analyze`).

With one POLICY, ``--json`` writes its record; with several, a list of records, and
``--markdown`` the comparison tables; ``--plots`` writes ``compliance_<policy>.png`` each.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import acld_gym
from acld_gym.benchmark import TEST_SETS
from acld_gym.util.atomic import check_directory, check_writable, write_json, write_text

from .analysis.control import Analysis, analyze
from .evaluate import add_score_episodes_argument, check_score_episodes

__all__ = ["analyze", "Analysis", "BASELINES", "resolve_policy", "main"]

#: The reference policies by name.
BASELINES = ("passive", "lqr", "smc", "mpc")


def resolve_policy(spec: str, env_id: str, env_kwargs: dict | None = None):
    """``(policy, name)`` for a baseline name or an agent directory; ``ValueError`` naming
    ``POLICY`` otherwise."""
    import gymnasium as gym

    if spec in BASELINES:
        from . import policies

        cls = {
            "passive": policies.PassivePolicy,
            "lqr": policies.LQRPolicy,
            "smc": policies.SMCPolicy,
            "mpc": policies.MPCPolicy,
        }[spec]
        env = gym.make(env_id, **(env_kwargs or {}))
        return cls.for_env(env), spec
    path = Path(spec)
    if not path.is_dir():
        raise ValueError(
            f"POLICY: expected one of {list(BASELINES)} or an agent directory, got {spec!r}"
        )
    from train.agent import TrainedAgent

    return TrainedAgent.load(path, path.name), path.name


def _finite(obj):
    """The record with non-finite floats as None (strict JSON)."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m baselines.analyze",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "policy",
        metavar="POLICY",
        nargs="+",
        help=f"one of {', '.join(BASELINES)}, or an agent directory",
    )
    p.add_argument(
        "--env-id",
        default=acld_gym.ENV_ID,
        choices=sorted(TEST_SETS),
        help=f"the env (default {acld_gym.ENV_ID})",
    )
    p.add_argument("--json", metavar="PATH", help="write the record as JSON")
    p.add_argument("--plots", metavar="DIR", help="write the compliance figures to DIR")
    p.add_argument("--markdown", metavar="PATH", help="write the comparison tables as markdown")
    add_score_episodes_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress line")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:  # unusable output paths and a bad POLICY fail now, before any computing
        for flag, path in (("--json", args.json), ("--markdown", args.markdown)):
            if path:
                check_writable(path, flag)
        if args.plots:
            check_directory(args.plots, "--plots")
        check_score_episodes(args.score_episodes, args.env_id)
        policies = [resolve_policy(spec, args.env_id) for spec in args.policy]
    except (OSError, ValueError) as exc:
        parser.error(str(exc))
    from .analysis.references import references
    from .analysis.report import format_analysis, markdown_summary, plot_compliance

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
        records = [_finite(r.as_dict()) for r in results]
        write_json(args.json, records[0] if len(records) == 1 else records)
        print(f"wrote {args.json}")
    if args.markdown:
        write_text(args.markdown, markdown_summary(results) + "\n")
        print(f"wrote {args.markdown}")
    return 0


if __name__ == "__main__":
    from acld_gym.util.validate import run_main

    sys.exit(run_main(main))
