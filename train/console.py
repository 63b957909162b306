"""The ``acld-gym`` command: one name for every tool of the package.

``acld-gym COMMAND [ARGS ...]`` runs the ``main(argv)`` of the module that :data:`COMMANDS`
names for ``COMMAND`` (a fixed table: nothing taken from the command line is imported
beyond it), with ``acld-gym COMMAND`` as the program name its help and errors show;
``acld-gym --help`` lists the commands, ``acld-gym --version`` prints the installed
version. Each command stays a ``python -m`` module too (``acld-gym evaluate`` is
``python -m baselines.evaluate``). The module sits at the top of the stack (physics ->
design -> envs -> baselines -> train), the only place that may import every layer.

A command whose module needs an install extra that is missing (the training commands
without ``acld-gym[train]``) ends with one line naming the extra to install, exit status 1;
an unknown command with one line and exit status 2.
"""

from __future__ import annotations

import difflib
import importlib
import importlib.util
import sys
from dataclasses import dataclass

__all__ = [
    "Command",
    "COMMANDS",
    "GROUPS",
    "EXTRA_MODULES",
    "module_names",
    "help_text",
    "version",
    "main",
]

PROG = "acld-gym"


@dataclass(frozen=True)
class Command:
    """One subcommand: the module whose ``main(argv)`` runs it, the one line
    ``acld-gym --help`` shows, the install extra it needs beyond the core (or ``None``) and
    the arguments put before the user's (the thesis commands share one parser)."""

    module: str
    summary: str
    extra: str | None = None
    lead: tuple[str, ...] = ()


def _thesis(name: str, summary: str) -> Command:
    return Command("acld_gym.thesis.cli", summary, lead=(name,))


#: The commands, by group, in the order ``acld-gym --help`` lists them.
GROUPS: dict[str, dict[str, Command]] = {
    "The thesis (its beam, mesh and controllers)": {
        "reproduce": _thesis("reproduce", "reproduce the thesis's Table 2 (--plots: its figures)"),
        "model": _thesis("model", "the model's natural frequencies, Hankel values, passive peak"),
        "mesh": _thesis("mesh", "mesh convergence: the thesis's mesh against the converged beam"),
        "params": _thesis("params", "print the beam's parameter table (Markdown)"),
    },
    "Controllers and agents on a level": {
        "evaluate": Command(
            "baselines.evaluate", "run and score every reference controller of a level"
        ),
        "analyze": Command(
            "train.analyze", "a controller or agent in control terms (modes, margins, effort)"
        ),
        "robustness": Command(
            "baselines.robustness", "stability of the reference controllers on varied beams"
        ),
        "compare": Command("train.compare", "the shipped agents against the reference controllers"),
        "ship": Command("train.ship", "copy a trained agent, checked, into a folder of agents"),
        "leaderboard": Command(
            "train.leaderboard.cli", "every level's references and agents, collected and rendered"
        ),
    },
    "Training (needs pip install 'acld-gym[train]')": {
        "train": Command("train.cli", "train one agent with a recipe (ppo, sac, vrs, ..)", "train"),
        "benchmark": Command(
            "train.benchmark", "train every recipe on several seeds and report them", "train"
        ),
        "report": Command(
            "train.core.report", "the benchmark's tables and curves from its results", "train"
        ),
        "sweep": Command(
            "train.sweep", "seeds x learning rates with Ray Tune (also acld-gym[sweep])", "sweep"
        ),
    },
}
#: Every command by name.
COMMANDS: dict[str, Command] = {name: c for group in GROUPS.values() for name, c in group.items()}

#: The top-level modules each install extra brings (pyproject.toml's optional dependencies).
EXTRA_MODULES: dict[str, tuple[str, ...]] = {
    "train": ("torch", "stable_baselines3", "sb3_contrib", "tensorboard", "yaml", "rich"),
    "sweep": ("ray",),
    "baselines": ("osqp",),
    "zoo": ("rl_zoo3",),
}


def version() -> str:
    """The version of the package that runs: ``acld_gym.__version__`` (an editable install's
    metadata keeps the version it was installed at; the code imported is what answers)."""
    import acld_gym

    return acld_gym.__version__


def help_text() -> str:
    """What ``acld-gym --help`` prints: every command with its one line, by group."""
    width = max(len(name) for name in COMMANDS) + 2
    lines = [
        f"usage: {PROG} [-h] [--version] COMMAND [ARGS ...]",
        "",
        "An actively damped cantilever beam as a Gymnasium benchmark: reproduce the thesis,",
        "evaluate the reference controllers, train, compare and ship agents.",
        f"'{PROG} COMMAND --help' explains a command and its options.",
    ]
    for title, commands in GROUPS.items():
        lines += ["", f"{title}:"]
        lines += [f"  {name:<{width}}{c.summary}" for name, c in commands.items()]
    lines += [
        "",
        "options:",
        f"  {'-h, --help':<{width}}show this help and exit",
        f"  {'--version':<{width}}print the version and exit",
        "",
        f"Each command is also a Python module: '{PROG} evaluate' is "
        "'python -m baselines.evaluate',",
        f"'{PROG} train' is 'python -m train'.",
    ]
    return "\n".join(lines)


def _absent(module: str) -> bool:
    """Whether ``module`` cannot be imported here (not installed, or refused by a finder)."""
    try:
        return importlib.util.find_spec(module) is None
    except (ImportError, ValueError):
        return True


def missing_extra(exc: ImportError, command: Command) -> tuple[str, str] | None:
    """``(extra, module)`` when ``exc`` comes from a module of an install extra that is not
    installed (a finder that refuses an import without naming it: the first absent module
    of the command's own extra); ``None`` for any other import error."""
    name = (exc.name or "").split(".")[0]
    for extra, modules in EXTRA_MODULES.items():
        if name in modules:
            return extra, name
    if not exc.name and command.extra is not None:
        absent = [m for m in EXTRA_MODULES[command.extra] if _absent(m)]
        if absent:
            return command.extra, absent[0]
    return None


def _unknown(word: str) -> str:
    """The one line for a first argument that names no command."""
    kind = "option" if word.startswith("-") else "command"
    close = difflib.get_close_matches(word, [*COMMANDS, "--help", "--version"], n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"{PROG}: error: unknown {kind} {word!r}{hint}; '{PROG} --help' lists the commands"


def module_names() -> dict[str, str]:
    """Each command's ``python -m`` module (a package's ``cli`` module is run as the package,
    ``python -m train``) -> its ``acld-gym`` command; the thesis commands share one module
    and are left out."""
    out = {}
    for name, c in COMMANDS.items():
        if c.lead:
            continue
        out[c.module.removesuffix(".cli")] = f"{PROG} {name}"
    return out


def run(name: str, argv: list[str]) -> int:
    """Run command ``name`` (a key of :data:`COMMANDS`) with the arguments ``argv``."""
    from acld_gym.util.text import invoked_as
    from acld_gym.util.validate import run_main

    command = COMMANDS[name]
    prog = f"{PROG} {name}"
    with invoked_as(prog, module_names()):
        try:
            module = importlib.import_module(command.module)
            return run_main(lambda: module.main([*command.lead, *argv]), prog)
        except ImportError as exc:
            missing = missing_extra(exc, command)
            if missing is None:
                raise
            extra, absent = missing
            print(
                f"{prog}: needs the {extra} extra ({absent} is not installed): "
                f"pip install 'acld-gym[{extra}]'",
                file=sys.stderr,
            )
            return 1


def main(argv: list[str] | None = None) -> int:
    """``acld-gym [--help | --version | COMMAND [ARGS ...]]``; the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv:
        print(help_text(), file=sys.stderr)
        return 2
    first, rest = argv[0], argv[1:]
    if first in ("-h", "--help"):
        print(help_text())
        return 0
    if first == "--version":
        print(f"{PROG} {version()}")
        return 0
    if first not in COMMANDS:
        print(_unknown(first), file=sys.stderr)
        return 2
    return run(first, rest)


if __name__ == "__main__":
    sys.exit(main())
