"""The ``acld-gym`` command (:mod:`train.console`) and the plain help of every tool
(:func:`acld_gym.util.text.plain`): every subcommand's ``--help`` in plain words under
``acld-gym SUB``, ``--version``, one line for an unknown command or a missing extra, the
``python -m`` forms unchanged."""

from __future__ import annotations

import importlib
import re
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from acld_gym.util.text import invoked_as, math_text, plain, prog
from tests.core_only import run_core_only
from train.console import COMMANDS, GROUPS, help_text, main, module_names

ROOT = Path(__file__).resolve().parents[1]
#: reStructuredText left in a help text: a role, a literal, a directive, a literal-block mark.
MARKUP = re.compile(r":[a-z]+:`|``|^\s*\.\. \w+::|::$", re.M)


def run(argv, capsys) -> tuple[int, str, str]:
    """``main(argv)`` in this process: (exit status, stdout, stderr)."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's --help and usage errors
        code = exc.code
    out = capsys.readouterr()
    return code, out.out, out.err


def test_help_lists_every_command_with_one_line(capsys):
    code, out, err = run(["--help"], capsys)
    assert code == 0 and err == ""
    assert out == help_text() + "\n"
    for name, command in COMMANDS.items():
        rows = [line for line in out.splitlines() if line.startswith(f"  {name} ")]
        assert len(rows) == 1 and rows[0].strip().endswith(command.summary), name
    assert "--version" in out and not MARKUP.search(out)
    assert max(len(line) for line in out.splitlines()) <= 100
    assert sum(len(group) for group in GROUPS.values()) == len(COMMANDS)


@pytest.mark.parametrize("name", list(COMMANDS))
def test_every_subcommand_help_is_plain_under_its_name(name, capsys):
    code, out, err = run([name, "--help"], capsys)
    assert code == 0, err
    assert out.startswith(f"usage: acld-gym {name} "), out[:80]
    assert not MARKUP.search(out), MARKUP.search(out)
    assert prog("python -m x") == "python -m x"  # the name does not outlive the command


def test_the_command_table_names_this_package_only():
    for name, command in COMMANDS.items():
        assert command.module.split(".")[0] in ("acld_gym", "baselines", "train"), name
        assert callable(importlib.import_module(command.module).main), name
    # a word from the command line is looked up in the table, never imported
    assert "os" not in COMMANDS and "train.console" not in COMMANDS


def test_version_is_the_running_package_and_the_project_file(capsys):
    import tomllib

    import acld_gym

    code, out, err = run(["--version"], capsys)
    assert (code, err) == (0, "")
    assert out == f"acld-gym {acld_gym.__version__}\n"
    project = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    assert project["project"]["version"] == acld_gym.__version__  # one version, two places


@pytest.mark.parametrize(
    "argv, hint",
    [(["evalute"], "'evaluate'"), (["--verbose", "params"], "option"), (["os", "-h"], "os")],
)
def test_an_unknown_command_is_one_line_and_exit_2(argv, hint, capsys):
    code, out, err = run(argv, capsys)
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and err.startswith("acld-gym: error: unknown"), err
    assert hint in err and "acld-gym --help" in err


def test_no_command_prints_the_list_and_exits_2(capsys):
    code, out, err = run([], capsys)
    assert code == 2 and out == "" and err == help_text() + "\n"


def test_subcommands_run_and_fail_under_their_name(capsys):
    code, out, _ = run(["params", "--preset", "table1"], capsys)
    assert code == 0 and out.startswith("| field | symbol | value | unit |")
    code, _, err = run(["evaluate", "--env-id", "Nope-v9"], capsys)
    assert code == 2
    assert err.splitlines()[-1].startswith("acld-gym evaluate: error: --env-id must be one of")
    code, _, err = run(["reproduce", "--t-end", "-1"], capsys)
    assert code == 2 and "acld-gym reproduce: error: argument --t-end" in err
    code, _, err = run(["model", "--json", f"{__file__}/x.json"], capsys)
    assert code == 2 and err.splitlines()[-1].startswith("acld-gym model: error: --json:")


def test_the_console_script_is_this_command():
    text = (ROOT / "pyproject.toml").read_text()
    scripts = re.search(r"^\[project\.scripts\]\n(.*?)(?:^\[|\Z)", text, re.M | re.S)[1]
    assert re.findall(r'^(\S+) = "(\S+)"$', scripts, re.M) == [("acld-gym", "train.console:main")]


def test_core_install_runs_the_command_and_names_the_missing_extra(tmp_path):
    code = (
        "import sys\n"
        "from train.console import main\n"
        "for argv in (['--version'], ['--help'], ['params'], ['evaluate', '--help'],"
        " ['compare', '--help']):\n"
        "    try:\n"
        "        assert main(argv) == 0, argv\n"
        "    except SystemExit as exc:\n"
        "        assert exc.code == 0, argv\n"
        "print('TRAIN', main(['train', 'ppo', '--seed', '0']))\n"
        "print('BENCH', main(['benchmark', '--help']))\n"
    )
    out = run_core_only(code, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "TRAIN 1" in out.stdout and "BENCH 1" in out.stdout, out.stdout
    want = (
        r"needs the train extra \((torch|yaml) is not installed\): pip install 'acld-gym\[train\]'"
    )
    lines = out.stderr.splitlines()
    assert len(lines) == 2, out.stderr
    assert re.fullmatch(f"acld-gym train: {want}", lines[0]), lines
    assert re.fullmatch(f"acld-gym benchmark: {want}", lines[1]), lines


@pytest.mark.parametrize(
    "module, usage",
    [("baselines.evaluate", "python -m baselines.evaluate"), ("train", "python -m train")],
)
def test_the_python_m_forms_still_work(module, usage):
    out = subprocess.run(
        [sys.executable, "-m", module, "--help"], capture_output=True, text=True, cwd=ROOT
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith(f"usage: {usage} ") and not MARKUP.search(out.stdout)


# --- plain ---------------------------------------------------------------------------


def test_plain_turns_roles_literals_and_math_into_words():
    doc = (
        "Run :func:`~baselines.evaluate.rollout` on :class:`acld_gym.envs.ACLDBeamEnv`\n"
        "(:mod:`baselines.marks`, :data:`the sets <acld_gym.test_sets.TEST_SETS>`): ``--json``\n"
        "writes `rows`; :math:`V = -K \\hat x_r` with :math:`e^{\\pm 3\\sigma}`.\n\n"
        ".. math::\n\n    x^+ &= A_d x + B_d V, \\\\\n\n"
        "Examples::\n\n    python -m train.benchmark \\\n        --seeds 0\n\n"
        "* ``results.md``: the\n  table;\n* two\n"
    )
    text = plain(doc, width=200)
    assert text.split("\n\n") == [
        "Run rollout on acld_gym.envs.ACLDBeamEnv (baselines.marks, the sets): --json writes rows;"
        " V = -K x\u0302_r with e^(± 3σ).",
        "    x⁺ = A_d x + B_d V,",
        "Examples:",
        "    python -m train.benchmark \\\n        --seeds 0",
        "* results.md: the table;\n* two",
    ]
    assert plain(None) == "" and plain("") == ""


def test_plain_fills_paragraphs_to_the_width():
    doc = "A " + "word " * 60 + "\n\n* item " + "x " * 50
    for width in (40, 72):
        lines = plain(doc, width=width).splitlines()
        assert max(len(line) for line in lines) <= width
        assert lines[lines.index("") + 1].startswith("* item") and lines[-1].startswith("  ")


@pytest.mark.parametrize("lead", range(0, 40, 3))
def test_plain_keeps_a_short_literal_on_one_line(lead):
    doc = "a " * lead + "``python -m train ppo --seed N`` then " + "b " * 20
    lines = plain(doc, width=40).splitlines()
    assert any("python -m train ppo --seed N" in line for line in lines), lines
    assert max(len(line) for line in lines) <= 40
    long = "x " * lead + "``" + "y " * 30 + "``"  # longer than a line: breaks, within width
    assert max(len(line) for line in plain(long, width=40).splitlines()) <= 40


def test_math_text():
    assert (
        math_text(r"\frac{a}{b} \le \alpha^{-1}, \mathrm{ISE}_{k+1}") == "(a)/(b) ≤ α⁻¹, ISE_(k+1)"
    )


WORDS = st.text("abcdefxyz_", min_size=1, max_size=8).filter(lambda w: w.strip("_"))
ROLES = st.sampled_from(["mod", "func", "class", "data", "meth", "attr", "py:func"])


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(WORDS, st.integers(0, 3), ROLES), min_size=1, max_size=30))
def test_plain_keeps_every_word_in_order_and_no_markup(parts):
    marked = {
        0: lambda w, r: w,
        1: lambda w, r: f"``{w}``",
        2: lambda w, r: f":{r}:`{w}`",
        3: lambda w, r: f":{r}:`~pkg.{w}`",
    }
    doc = " ".join(marked[kind](word, role) for word, kind, role in parts)
    text = plain(doc, width=60)
    assert not MARKUP.search(text) and "`" not in text
    assert text.split() == [word for word, _, _ in parts]


def test_invoked_as_is_scoped():
    assert prog("python -m a") == "python -m a"
    with invoked_as("acld-gym a"):
        assert prog("python -m a") == "acld-gym a"
    assert prog("python -m a") == "python -m a"


def test_command_names_only_inside_the_command_and_only_whole_modules():
    text = "python -m train.ship RUN; python -m train --seed 1; python -m train.shipx; python -m x"
    names = {"train.ship": "acld-gym ship", "train": "acld-gym train"}
    assert plain(text, width=200) == text  # outside acld-gym: unchanged
    with invoked_as("acld-gym ship", names):
        got = plain(text, width=200)
    assert got == "acld-gym ship RUN; acld-gym train --seed 1; python -m train.shipx; python -m x"
    assert plain(text, width=200) == text  # and scoped


@pytest.mark.parametrize("name", [n for n, c in COMMANDS.items() if not c.lead])
def test_a_subcommand_help_names_tools_by_their_command(name, capsys):
    """Run as ``acld-gym NAME --help``, the help names no tool by a ``python -m`` form that
    has an ``acld-gym`` command (the ship command's own text said 'python -m train.ship RUN
    NAME' under 'usage: acld-gym ship')."""
    code, out, _ = run([name, "--help"], capsys)
    assert code == 0
    for module in module_names():
        assert not re.search(rf"python -m {re.escape(module)}(?![\w]|\.\w)", out), (module, out)
    module = COMMANDS[name].module.removesuffix(".cli")
    assert module_names()[module] == f"acld-gym {name}"


@pytest.mark.parametrize("name", list(COMMANDS))
def test_every_python_m_form_has_the_same_plain_help(name, capsys):
    """The module a subcommand runs, called as its ``python -m`` form: its usage names that
    form (not ``acld-gym``), and its help has no reStructuredText either."""
    command = COMMANDS[name]
    try:
        code = importlib.import_module(command.module).main([*command.lead, "--help"])
    except SystemExit as exc:
        code = exc.code
    out = capsys.readouterr().out
    assert code == 0
    # the thesis's commands were acld-gym's own before the others joined: no python -m form
    form = (
        f"acld-gym {name} " if command.lead else f"python -m {command.module.removesuffix('.cli')}"
    )
    assert out.startswith(f"usage: {form}"), out[:80]
    assert not MARKUP.search(out), MARKUP.search(out)
