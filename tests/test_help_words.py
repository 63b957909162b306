"""The help of ``acld-gym benchmark``, ``report``, ``train`` and ``compare`` is for a user:
every option says what it does, and no text names one of the package's functions (a user
cannot act on ``write_blocks`` or ``run_trial``; the text says what happens instead)."""

from __future__ import annotations

import importlib
import inspect
import re
import sys

import pytest

from tests.test_console import run
from train.console import COMMANDS

NAMES = ("benchmark", "report", "train", "compare")
PACKAGES = ("acld_gym", "baselines", "train")
#: an option row of argparse's help: the flag at two spaces, then its text on the same
#: line (after two spaces or more) or on the next, deeper-indented line
OPTION = re.compile(r"^  (-{1,2}[\w-]+)(.*)$")


#: words of the help that are also a function's name elsewhere: keys of the --json rows
KEYS = frozenset({"ise_rel_lqr"})


def package_functions() -> set[str]:
    """The names, with an underscore inside (the ones that read as code: ``write_blocks``,
    not ``main``), of the package's functions in every loaded module of it: the four
    commands' modules and what they import, and the trial code ``train`` runs."""
    for name in NAMES:
        importlib.import_module(COMMANDS[name].module)
    importlib.import_module("train.core.trials")
    names = set()
    modules = [m for n, m in list(sys.modules.items()) if n.split(".")[0] in PACKAGES and m]
    for module in modules:
        for key, value in list(vars(module).items()):
            home = getattr(value, "__module__", "") or ""
            if inspect.isfunction(value) and home.split(".")[0] in PACKAGES:
                if "_" in key.strip("_"):
                    names.add(key)
    return names - KEYS


def options_without_help(text: str) -> list[str]:
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("options:"))
    bad = []
    for i in range(start + 1, len(lines)):
        match = OPTION.match(lines[i])
        if not match or match[1] in ("-h", "--help"):
            continue
        same_line = re.search(r"\S\s{2,}\S", lines[i][2:])
        following = (
            i + 1 < len(lines)
            and lines[i + 1].startswith(" " * 8)
            and (not OPTION.match(lines[i + 1]))
        )
        if not same_line and not following:
            bad.append(match[1])
    return bad


def test_the_checks_see_a_missing_help_and_a_function_name():
    text = "options:\n  -h, --help  show\n  --seeds SEEDS [SEEDS ...]\n  --out OUT   folder\n"
    assert options_without_help(text) == ["--seeds"]
    wrapped = "options:\n  --cpus-per-trial CPUS_PER_TRIAL\n          CPUs of a trial\n"
    assert options_without_help(wrapped) == []
    functions = package_functions()
    for removed in ("write_blocks", "plot_curves", "run_trial", "reference_policies"):
        assert removed in functions, removed
    assert "main" not in functions


@pytest.mark.parametrize("name", NAMES)
def test_every_option_has_help_and_no_function_is_named(name, capsys):
    code, out, err = run([name, "--help"], capsys)
    assert code == 0, err
    assert options_without_help(out) == []
    named = sorted(f for f in package_functions() if re.search(rf"\b{f}\b", out))
    assert named == [], named
