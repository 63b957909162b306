"""Every ```python block of the README runs, and every value it claims is what it prints.

The blocks run in order in one namespace, as a reader runs them. A line of the form
``expression  # -> 1.23, 4.5e-08  [unit, ...]`` is checked: the expression is evaluated
and its numbers (flattened, in order) must round to the numbers after ``->`` at their
printed precision (half a unit in the last printed digit). Commentary starts at two
spaces and a bracket (``  [mm]``) or at a semicolon. Provenance: the README's claims.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def python_blocks(text: str) -> list[str]:
    """The README's ```python blocks, in order."""
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def claims(block: str) -> list[tuple[int, str, str]]:
    """``(line number, expression, claimed text)`` for each ``expr  # -> claim`` line."""
    out = []
    for i, line in enumerate(block.splitlines()):
        code, sep, comment = line.partition("# ->")
        if sep and code.strip():
            claim = re.split(r"\s{2,}\[|;", comment, maxsplit=1)[0]
            out.append((i, code.strip(), claim))
    return out


def half_unit(text: str) -> float:
    """Half a unit in the last printed digit of a number as printed."""
    mantissa, _, exponent = text.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 0.5 * 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def numbers(value) -> list[float]:
    """The numbers of a value (scalars, arrays, tuples, lists), flattened in order."""
    if isinstance(value, (tuple, list)):
        return [x for v in value for x in numbers(v)]
    return [float(x) for x in np.ravel(np.asarray(value, dtype=float))]


def run_block(block: str, namespace: dict, where: str = "README block") -> list[str]:
    """Runs a block statement by statement; checks each claim. Returns the mismatches."""
    lines = block.splitlines()
    checks = {i: (expr, claim) for i, expr, claim in claims(block)}
    failures = []
    for node in ast.parse(block).body:
        source = "\n".join(lines[node.lineno - 1 : node.end_lineno])
        claim = checks.get(node.end_lineno - 1)
        if claim is None or not isinstance(node, ast.Expr):
            exec(compile(ast.Module([node], []), where, "exec"), namespace)
            continue
        value = eval(compile(ast.Expression(node.value), where, "eval"), namespace)
        if claim[1].strip().startswith(("'", '"')):  # a string claim: equal as written
            if value != ast.literal_eval(claim[1].strip()):
                failures.append(f"{source!r}: got {value!r}, README says {claim[1].strip()}")
            continue
        printed = NUMBER.findall(claim[1])
        got = numbers(value)
        if len(got) != len(printed):
            failures.append(f"{source!r}: {len(got)} numbers, README prints {printed}")
            continue
        for g, p in zip(got, printed, strict=True):
            if abs(g - float(p)) > half_unit(p) * (1 + 1e-9):
                failures.append(f"{source!r}: got {g:.6g}, README says {p}")
    return failures


def test_claim_parser_on_examples():
    block = "x = 2\n(x * 0.3333, 1e-8)  # -> (0.667, 1.0e-08)  [mm, m^2 s]\n[x]  # -> [2.0]\n"
    assert claims(block)[0] == (1, "(x * 0.3333, 1e-8)", " (0.667, 1.0e-08)")
    assert claims(block)[1] == (2, "[x]", " [2.0]")
    assert run_block(block, {}) == []
    assert run_block("s = 'ab'\ns  # -> 'ab'  [text]\n", {}) == []
    assert len(run_block("s = 'ab'\ns  # -> 'abc'\n", {})) == 1
    bad = "x = 2\nx * 0.3334  # -> 0.666\n"
    assert run_block(bad, {}) and half_unit("2.5e-08") == pytest.approx(0.05e-08)


BLOCKS = python_blocks(README.read_text())


def test_readme_has_the_quick_starts():
    assert len(BLOCKS) >= 3
    assert any("gym.make(\"ACLDBeam-v1\"" in b for b in BLOCKS)


@pytest.fixture(scope="module")
def namespace():
    """One namespace for all blocks, in README order (a block may use an earlier one's)."""
    return {"__name__": "__readme__"}


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_block(index, namespace, monkeypatch):
    monkeypatch.chdir(README.parent)
    failures = run_block(BLOCKS[index], namespace, f"README python block {index}")
    assert not failures, "\n".join(failures)
