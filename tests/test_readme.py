"""Every ```python block of the README runs, and every value it claims is what it prints
(the rules: :mod:`tests.doc_blocks`). Provenance: the README's claims.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.doc_blocks import claims, half_unit, python_blocks, run_block

README = Path(__file__).resolve().parents[1] / "README.md"


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
    assert any('gym.make("ACLDBeam-v1"' in b for b in BLOCKS)


@pytest.fixture(scope="module")
def namespace():
    """One namespace for all blocks, in README order (a block may use an earlier one's)."""
    return {"__name__": "__readme__"}


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_block(index, namespace, monkeypatch):
    monkeypatch.chdir(README.parent)
    failures = run_block(BLOCKS[index], namespace, f"README python block {index}")
    assert not failures, "\n".join(failures)
