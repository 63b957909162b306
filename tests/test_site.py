"""The documentation site: the role rewriter of docs/griffe_ext, and a strict build whose
HTML holds no unrendered Sphinx role, no raw RST literal and no sentence in a Type column."""

from __future__ import annotations

import html
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "griffe_ext"))
from rst_to_md import rewrite  # noqa: E402

KNOWN = {
    "EnvConfig": "acld_gym.envs.config.EnvConfig",
    "acld_gym.envs.config.EnvConfig": "acld_gym.envs.config.EnvConfig",
    "acld_gym.util.atomic.write_text": "acld_gym.util.atomic.write_text",
}


def resolve(target):
    return KNOWN.get(target)


def test_roles_become_autorefs_or_code():
    text = "See :class:`EnvConfig`, :func:`~acld_gym.util.atomic.write_text` and :mod:`numpy`."
    assert rewrite(text, resolve) == (
        "See [`EnvConfig`][acld_gym.envs.config.EnvConfig], "
        "[`write_text`][acld_gym.util.atomic.write_text] and `numpy`."
    )


def test_title_bang_parentheses_and_py_domain():
    assert rewrite(":py:class:`the config <EnvConfig>`", resolve) == (
        "[`the config`][acld_gym.envs.config.EnvConfig]"
    )
    assert rewrite(":class:`!EnvConfig`", resolve) == "`EnvConfig`"
    assert rewrite(":func:`~acld_gym.util.atomic.write_text()`", resolve) == (
        "[`write_text()`][acld_gym.util.atomic.write_text]"
    )


def test_role_over_a_line_break_and_math_and_literals():
    text = "a role over two lines :class:`acld_gym.envs.config.\n    EnvConfig` here"
    assert rewrite(text, resolve) == (
        "a role over two lines [`acld_gym.envs.config.EnvConfig`][acld_gym.envs.config.EnvConfig]"
        " here"
    )
    assert rewrite(r"cost :math:`x^T Q x` and ``dt``", resolve) == r"cost \(x^T Q x\) and `dt`"
    # a literal holding backticks (and a role) keeps a double fence, its role untouched
    assert rewrite("(``:math:`x^+```) and ``a``", resolve) == "(`` :math:`x^+` ``) and `a`"
    assert rewrite("``:class:`EnvConfig``` :class:`EnvConfig`", resolve) == (
        "`` :class:`EnvConfig` `` [`EnvConfig`][acld_gym.envs.config.EnvConfig]"
    )


def test_code_doctest_and_literal_blocks_are_left_alone():
    text = (
        "Text :class:`EnvConfig`.\n\n"
        "```python\nx = ':class:`EnvConfig`' and ``y``\n```\n\n"
        ">>> f(':func:`g`')  # ``z``\n':func:`g`'\n\n"
        "Example::\n\n    run(':mod:`m`', ``w``)\n\n"
        "After :mod:`numpy`."
    )
    out = rewrite(text, resolve)
    assert "x = ':class:`EnvConfig`' and ``y``" in out
    assert ">>> f(':func:`g`')  # ``z``\n':func:`g`'" in out
    assert "Example:\n\n    run(':mod:`m`', ``w``)" in out
    assert out.startswith("Text [`EnvConfig`][acld_gym.envs.config.EnvConfig].")
    assert out.endswith("After `numpy`.")


def test_display_math_becomes_a_formula():
    out = rewrite("Intro\n\n.. math::\n\n    x_{k+1} = A x_k\n      + B u_k\n\nafter", resolve)
    assert ".. math::" not in out
    assert "\n\\[\nx_{k+1} = A x_k\n+ B u_k\n\\]\n" in out and out.endswith("\nafter")
    # the expression on the directive's line; indented, as in a Parameters entry
    assert rewrite(".. math:: a = b\n\nafter", resolve).startswith("\n\\[\na = b\n\\]\n")
    assert "\n    \\[\n    a\n    \\]\n" in rewrite("x\n    .. math:: a\ny", resolve)
    # under a list item's text (2 deeper): at the list's own indentation
    assert "\n\\[\na\n\\]\n" in rewrite("* item\n  text:\n\n  .. math:: a\n\nafter", resolve)
    # at the end of the text
    assert rewrite(".. math:: a", resolve).endswith("\\[\na\n\\]\n")


def test_a_wrapped_table_cell_is_one_cell():
    rows = ["| a | b | c |", "|---|---|---|", "| x | 1 | one and |", "| | | two |", "| | | three |"]
    text = "\n".join([*rows, "| y | 2 | z |"])
    out = rewrite(text, resolve).split("\n")
    assert out == [
        "| a | b | c |",
        "|---|---|---|",
        "| x | 1 | one and two three |",
        "| y | 2 | z |",
    ]
    # no table: a line of bars alone is not joined to prose
    assert rewrite("prose\n| | | x |", resolve).split("\n") == ["prose", "| | | x |"]


def test_the_env_arguments_table_has_no_row_of_empty_cells():
    """The env's docstring wraps its long cells as rows of empty cells (for ``help()``); on
    the site each argument is one row."""
    from acld_gym.envs.beam_env import ACLDBeamEnv

    out = rewrite(ACLDBeamEnv.__doc__, resolve)
    rows = [line.strip() for line in out.split("\n") if line.strip().startswith("|")]
    assert len(rows) > 20
    assert not [r for r in rows if r.startswith("| |")], "a continued row was left"
    assert any("`TipLoad` (pulses" in r and "`load_case`" in r for r in rows)


def test_sentences_in_type_slots_move_to_the_description():
    doc = (
        "Parameters\n----------\n"
        "dt : control period [s], > 0.\n"
        "A, B : state matrix (n x n), input (n x 1).\n"
        "x : float, optional\n    The value; see :class:`EnvConfig`.\n"
        "config : :class:`EnvConfig`\n    Where.\n"
        "env : gymnasium.vector.VectorEnv\n    A vector env.\n\n"
        "Returns\n-------\n"
        "T, Tinv : the transformation and its inverse (n x n).\n"
        "score : the policy's score on the level.\n"
        "The score as a float, between 0 and 1.\n"
        "float\n    A number.\n"
    )
    out = rewrite(doc, resolve).split("\n")
    assert out[2:4] == ["dt", "    control period [s], > 0."]
    assert out[4:6] == ["A, B", "    state matrix (n x n), input (n x 1)."]
    assert out[6] == "x : float, optional"  # a type stays
    assert out[7] == "    The value; see [`EnvConfig`][acld_gym.envs.config.EnvConfig]."
    assert out[8] == "config : EnvConfig"  # a role as type: the name, for griffe to parse
    assert out[10] == "env : gymnasium.vector.VectorEnv"  # a dotted path is one type
    out = out[:10] + out[12:]
    assert out[13:15] == [":", "    `T, Tinv`: the transformation and its inverse (n x n)."]
    assert out[15:17] == ["score :", "    the policy's score on the level."]
    assert out[17:19] == [":", "    The score as a float, between 0 and 1."]
    assert out[19] == "float"


NAME = st.from_regex(r"[A-Za-z_]\w{0,8}(\.[A-Za-z_]\w{0,8}){0,3}", fullmatch=True)
ROLE = st.sampled_from(["class", "func", "meth", "mod", "data", "attr", "math"])


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.text(alphabet="ab ,.()\n", max_size=8), ROLE, NAME), max_size=6))
def test_no_role_survives_in_prose(parts):
    # any prose of roles: none survives, known names link, and the words are kept
    text = "".join(f"{pre}:{role}:`~{name}`" for pre, role, name in parts)
    out = rewrite(text, lambda t: f"pkg.{t}" if t.startswith("a") else None)
    assert not re.search(r":(class|func|meth|mod|data|attr|math):`", out)
    for _, role, name in parts:
        if role == "math":  # arithmatex's inline math, for MathJax
            assert f"\\(~{name}\\)" in out
        else:
            assert f"`{name.rsplit('.', 1)[-1]}`" in out


ROLE_LEFT = re.compile(r":(?:class|func|mod|meth|data|attr|math|obj|exc):(?:`|<code>)")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1", "OMP_NUM_THREADS": "1"}
    mkdocs = [sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(out)]
    run = subprocess.run(mkdocs, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    return {p.relative_to(out).as_posix(): p.read_text() for p in out.rglob("*.html")}


def _outside_code(text: str) -> str:
    # a role inside a code span or block is shown on purpose (acld_gym.util.text documents
    # the syntax); an unrendered role is the role's name before a <code> or a backtick
    text = re.sub(r"<pre.*?</pre>", "", text, flags=re.S)
    return re.sub(r"<code>.*?</code>", "<code></code>", text, flags=re.S)


#: LaTeX commands the docstrings' math uses; outside a formula they are its source shown raw
LATEX = re.compile(r"\\(frac|hat|sqrt|mathrm|sum|left|dot|tanh|log)\b")


def test_api_math_is_marked_for_mathjax(site):
    """Every docstring formula of the API pages reaches the page as arithmatex's markup
    (MathJax typesets it; the page loads MathJax), and no LaTeX command is left outside a
    formula or a code span (the site showed ~200, as code, before)."""
    api = {k: v for k, v in site.items() if k.startswith("api/")}
    marked = sum(v.count('class="arithmatex"') for v in api.values())
    assert marked > 300, marked
    for name, page in api.items():
        assert "mathjax" in page.lower(), name
        prose = re.sub(
            r'<(span|div) class="arithmatex">.*?</\1>', "", _outside_code(page), flags=re.S
        )
        left = LATEX.search(prose)
        assert left is None, (name, prose[max(0, left.start() - 80) : left.end() + 80])


def test_site_has_no_unrendered_roles_or_literals(site):
    roles = {page: len(ROLE_LEFT.findall(_outside_code(text))) for page, text in site.items()}
    assert sum(roles.values()) == 0, {p: n for p, n in roles.items() if n}
    literals = {
        page: re.sub(r"<pre.*?</pre>", "", text, flags=re.S).count("``")
        for page, text in site.items()
    }
    assert sum(literals.values()) == 0, {p: n for p, n in literals.items() if n}


def test_api_links_and_type_columns(site):
    api = "".join(text for page, text in site.items() if page.startswith("api/"))
    # the roles became links (there were 29 links before the extension, about 1000 after)
    assert api.count('class="autorefs autorefs-internal"') > 500
    sentences = []
    for table in re.findall(r"<table>(.*?)</table>", api, re.S):
        head = re.findall(r"<th>(.*?)</th>", table)
        if "Type" not in head:
            continue
        for row in re.findall(r"<tr[^>]*>(.*?)</tr>", table, re.S):
            cells = re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)
            if len(cells) > head.index("Type"):
                typ = html.unescape(re.sub("<[^>]+>", "", cells[head.index("Type")])).strip()
                if typ.endswith(".") or len(typ.split()) > 6:
                    sentences.append(typ)
    assert not sentences, sentences[:10]


#: a parameter table's Description that opens with a type: a dotted path
#: (``gymnasium.vector.VectorEnv The env ...``) or a numpydoc container type
TYPE_FIRST = re.compile(
    r"(?:[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)+|(?:sequence|list|tuple|dict|iterable|mapping) of \w+)"
    r"[,\s]"
)
SECTION = re.compile(r'doc-section-title">(\w+):</span></p>\s*<table>(.*?)</table>', re.S)


def _text(cell: str) -> str:
    return " ".join(html.unescape(re.sub("<[^>]+>", "", cell)).split())


def misplaced_types(page: str) -> list[tuple[str, list[str]]]:
    """Rows of a page's typed sections whose Description starts with a type (the
    docstring's type moved out of the Type column) or, for a parameter or attribute, is
    empty, and rows whose Type holds a whole ``name : type`` line."""
    bad = []
    for kind, table in SECTION.findall(page):
        head = re.findall(r"<th>(.*?)</th>", table)
        if "Description" not in head:
            continue
        col, typ = head.index("Description"), head.index("Type") if "Type" in head else None
        for row in re.findall(r"<tr[^>]*>(.*?)</tr>", table, re.S):
            cells = [_text(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
            if len(cells) <= col:
                continue
            empty = kind in ("Parameters", "Attributes") and not cells[col]
            named = typ is not None and " : " in cells[typ]
            if empty or named or TYPE_FIRST.match(cells[col]):
                bad.append((kind, cells))
    return bad


def test_misplaced_types_are_found():
    def table(kind, *rows):
        body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in rows)
        head = "<th>Name</th><th>Type</th><th>Description</th>"
        return f'<p><span class="doc-section-title">{kind}:</span></p>\n<table>{head}{body}</table>'

    good = table("Parameters", ("env", "VectorEnv", "A vector env. See <code>a.b</code>."))
    assert misplaced_types(good) == []
    moved = table("Parameters", ("env", "", "gymnasium.vector.VectorEnv A vector env."))
    assert misplaced_types(moved) == [
        ("Parameters", ["env", "", "gymnasium.vector.VectorEnv A vector env."])
    ]
    for desc in ("sequence of callables env -> env The wrappers.", "a.b.C, optional The x."):
        assert len(misplaced_types(table("Parameters", ("x", "", desc)))) == 1
    assert len(misplaced_types(table("Attributes", ("passthrough", "int", "")))) == 1
    assert misplaced_types(table("Returns", ("", "BoundSolution", ""))) == []
    assert len(misplaced_types(table("Returns", ("", "(low, high) : tuple of float", "")))) == 1


def test_types_stay_in_the_type_column(site):
    bad = {page: misplaced_types(text) for page, text in site.items() if page.startswith("api/")}
    assert not any(bad.values()), {page: rows[:5] for page, rows in bad.items() if rows}


def test_public_api_comes_first(site):
    public = site["api/public/index.html"]
    headings = re.findall(r'<h[23][^>]*id="([^"]+)"', public)
    for name in (
        "acld_gym.envs.presets",
        "acld_gym.envs.config.EnvConfig",
        "acld_gym.envs.vector_env.ACLDBeamVectorEnv",
        "acld_gym.envs.sb3.SB3VecEnv",
        "acld_gym.wrappers",
        "baselines.policies",
        "train.agent.TrainedAgent",
        "acld_gym.test_sets",
    ):
        assert name in headings, name
    # each is documented once: the internals pages filter the public names out
    internals = "".join(
        text for page, text in site.items() if page.startswith("api/") and "public" not in page
    )
    for name in ("acld_gym.envs.config.EnvConfig", "train.agent.TrainedAgent"):
        assert f'id="{name}"' not in internals, name
    home = site["index.html"]  # the navigation: the public page before the internals
    assert home.index("Public API") < home.index("acld_gym.envs internals")
