"""The thesis's commands of ``acld-gym`` (:mod:`train.console`): ``reproduce`` (Table 2),
``model`` (model facts), ``mesh`` (mesh convergence, thesis mesh vs converged plant),
``params``. ``acld-gym reproduce ...`` runs ``main(["reproduce", ...])``."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from acld_gym.design.pipeline import design
from acld_gym.design.simulate import simulate
from acld_gym.physics.loads import THESIS_CASES, thesis_load
from acld_gym.physics.params import PRESETS, parameter_table
from acld_gym.thesis.mesh_study import format_mesh_report, mesh_report
from acld_gym.thesis.metrics import peak
from acld_gym.thesis.reproduce import CONTROLLERS, T_END, format_table2, run_cases
from acld_gym.util.atomic import check_directory, check_writable, write_files, write_json
from acld_gym.util.progress import Progress
from acld_gym.util.text import plain
from acld_gym.util.validate import arg_type, run_main

__all__ = ["main"]


def _write_json(path: str, obj) -> None:
    write_json(path, obj)


def _check_outputs(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse unusable ``--json`` / ``--plots`` paths before any computing (exit 2)."""
    try:
        if getattr(args, "json", None):
            check_writable(args.json, "--json")
        if getattr(args, "plots", None):
            check_directory(args.plots, "--plots")
    except ValueError as exc:
        parser.error(str(exc))


def cmd_reproduce(args: argparse.Namespace) -> int:
    t0 = time.perf_counter()
    d = design(preset=args.preset)
    plots = Path(args.plots) if args.plots else None
    files: dict[Path, bytes] = {}  # every output, written at the end all or none
    if plots is not None:
        from acld_gym.thesis.plots import (  # matplotlib (~0.3 s): only --plots draws
            plot_frequency_response,
            plot_hankel,
            plot_response,
        )

        plot_hankel(plots / "hankel_singular_values.png", d, files)
        plot_frequency_response(plots / "frequency_response.png", d, files)

    def on_start(case, controller, saturation):
        bar.stage(f"case {case} · {controller} · {'saturated' if saturation else 'unsaturated'}")

    def on_result(row, res):
        if plots is not None:
            sat = "sat" if row.saturation else "nosat"
            title = (
                f"Case {row.case}: {row.controller.upper()} "
                f"{'with' if row.saturation else 'without'} saturation"
            )
            plot_response(
                plots / f"case{row.case}_{row.controller}_{sat}.png",
                res.t,
                res.y,
                res.voltage,
                title,
                load=res.load,
                out=files,
            )

    with Progress(2 * len(THESIS_CASES) * len(CONTROLLERS), "reproduce", args.quiet) as bar:
        rows = run_cases(
            d, observer=args.observer, t_end=args.t_end, on_result=on_result, on_start=on_start
        )
    print(format_table2(rows, t_end=args.t_end))
    print(
        f"\n{len(rows)} rows in {time.perf_counter() - t0:.2f} s "
        f"(observer: {args.observer}; settling = last exit from the 5% band of the peak "
        f"within {args.t_end:g} s)"
    )
    if args.json:
        files[Path(args.json)] = (json.dumps([r.as_dict() for r in rows], indent=2) + "\n").encode()
    write_files(files)
    if args.json:
        print(f"wrote {args.json}")
    if plots is not None:
        print(f"wrote figures to {plots}/")
    return 0


def cmd_model(args: argparse.Namespace) -> int:
    d = design(preset=args.preset)
    m = d.truth
    A, B, E, Cy = d.plant
    res = simulate(
        A, B, E, Cy, d.observer("thesis"), d.passive, thesis_load(1), t_end=T_END, v_max=None
    )
    out = {
        "preset": args.preset,
        "n_states": m.n_states,
        "natural_frequencies_rad_s": m.natural_frequencies().tolist(),
        "hankel_singular_values": d.reduced.hsv.tolist(),
        "passive_case1_peak_mm": peak(res.y) * 1e3,
    }
    print(
        f"preset {args.preset}: {m.n_states} states; first natural frequencies "
        f"{np.array2string(m.natural_frequencies()[:4], precision=1)} rad/s; "
        f"passive case-1 peak {out['passive_case1_peak_mm']:.4f} mm"
    )
    if args.json:
        _write_json(args.json, out)
        print(f"wrote {args.json}")
    return 0


def cmd_mesh(args: argparse.Namespace) -> int:
    t0 = time.perf_counter()
    rep = mesh_report()
    print(format_mesh_report(rep))
    print(f"\n({time.perf_counter() - t0:.1f} s)")
    if args.json:
        _write_json(args.json, rep)
        print(f"wrote {args.json}")
    return 0


def cmd_params(args: argparse.Namespace) -> int:
    print(parameter_table(PRESETS[args.preset]()))
    return 0


#: Each command's help: its first sentence for the list, all of it for its own ``--help``.
COMMANDS = {
    "reproduce": "Reproduce the thesis's Table 2 (and figures). Simulates the thesis's beam, on "
    "its own mesh and design model, passive and under LQR and SMC, with and without the "
    "+/-120 V limit, on the three load cases, and prints the peak, the settling time and "
    "the largest voltage beside the thesis's values.",
    "model": "Natural frequencies, Hankel values, passive peak. The facts of a preset's "
    "model: its states, first natural frequencies, the Hankel singular values of the "
    "reduction, and the passive beam's peak on load case 1.",
    "mesh": "Mesh convergence; the thesis mesh against the converged plant. The numbers of "
    "docs/mesh.md: the modes as the mesh is refined, the two plants and their design "
    "models, and the thesis's passive and LQR responses on each.",
    "params": "Print the parameter table (Markdown). Every parameter of a preset with its "
    "symbol, value, unit and description.",
}


def _command(sub, name: str) -> argparse.ArgumentParser:
    text = COMMANDS[name]
    return sub.add_parser(name, help=text.split(". ")[0], description=text)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="acld-gym", description=plain(__doc__))
    sub = p.add_subparsers(dest="command", required=True)
    r = _command(sub, "reproduce")
    r.add_argument("--json", metavar="PATH", help="write the rows as JSON")
    r.add_argument("--plots", metavar="DIR", help="write figures (PNG) to DIR")
    r.add_argument("--preset", choices=sorted(PRESETS), default="matlab")
    r.add_argument(
        "--observer",
        choices=["thesis", "thesis-unfed", "kalman"],
        default="thesis",
        help="'thesis' = the thesis observer fed the tip load (reproduces Table 2)",
    )
    r.add_argument(
        "--t-end",
        type=arg_type(float, 0.0, 100.0, low_open=True),
        default=T_END,
        help="simulated window [s]",
    )
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.set_defaults(func=cmd_reproduce, parser=r)
    m = _command(sub, "model")
    m.add_argument("--json", metavar="PATH", help="write the facts as JSON")
    m.add_argument("--preset", choices=sorted(PRESETS), default="matlab")
    m.set_defaults(func=cmd_model, parser=m)
    me = _command(sub, "mesh")
    me.add_argument("--json", metavar="PATH", help="write the numbers as JSON")
    me.set_defaults(func=cmd_mesh, parser=me)
    pa = _command(sub, "params")
    pa.add_argument("--preset", choices=sorted(PRESETS), default="matlab")
    pa.set_defaults(func=cmd_params, parser=pa)
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    _check_outputs(args.parser, args)  # its errors under 'acld-gym <command>'
    # one BLAS thread, a quiet end if the reader closes the pipe (acld-gym params | head -1),
    # one line for a failed write (a full disk)
    return run_main(lambda: args.func(args), "acld-gym")


if __name__ == "__main__":
    sys.exit(main())
