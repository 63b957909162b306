"""Running a page's code blocks as a reader runs them, and checking the values it claims:
shared by the README's test (:mod:`tests.test_readme`) and the documentation's
(:mod:`tests.test_docs`).

The ```python blocks run in order in one namespace. A line of the form
``expression  # -> 1.23, 4.5e-08  [unit, ...]`` is checked: the expression is evaluated
and its numbers (flattened, in order) must round to the numbers after ``->`` at their
printed precision (half a unit in the last printed digit); a quoted claim must be equal
as written. Commentary starts at two spaces and a bracket (``  [mm]``) or at a semicolon.
"""

from __future__ import annotations

import ast
import re

import numpy as np

__all__ = ["python_blocks", "claims", "half_unit", "numbers", "run_block", "run_page"]

NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def python_blocks(text: str) -> list[str]:
    """A page's ```python blocks, in order."""
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


def run_block(block: str, namespace: dict, where: str = "block") -> list[str]:
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
                failures.append(f"{source!r}: got {value!r}, the page says {claim[1].strip()}")
            continue
        printed = NUMBER.findall(claim[1])
        got = numbers(value)
        if len(got) != len(printed):
            failures.append(f"{source!r}: {len(got)} numbers, the page prints {printed}")
            continue
        for g, p in zip(got, printed, strict=True):
            if abs(g - float(p)) > half_unit(p) * (1 + 1e-9):
                failures.append(f"{source!r}: got {g:.6g}, the page says {p}")
    return failures


def run_page(text: str, namespace: dict, where: str) -> list[str]:
    """Runs every ```python block of a page in ``namespace``; the claims that fail."""
    failures = []
    for i, block in enumerate(python_blocks(text)):
        failures += run_block(block, namespace, f"{where} python block {i}")
    return failures
