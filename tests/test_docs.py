"""The documentation pages under ``docs/``: every ```python block runs and every value it
claims is what it prints (the README's rules, :mod:`tests.test_readme`), and each reference
table of ``docs/variants.md`` is what its command prints today (all columns but the
timings)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.test_readme import python_blocks, run_block

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = sorted(DOCS.glob("*.md"))


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_python_blocks_run_and_claims_hold(page):
    namespace: dict = {}
    failures = []
    for block in python_blocks(page.read_text()):
        failures += run_block(block, namespace, where=page.name)
    assert failures == []


def _rows(text: str) -> list[list[str]]:
    """The policy rows of evaluation tables, without the ms/step column."""
    return [line.split()[:-1] for line in text.splitlines()
            if re.match(r"^\s+(passive|lqr|smc|mpc|bound)\s", line)]


def test_variant_tables_are_what_their_commands_print(capsys):
    from baselines.evaluate import main

    text = (DOCS / "variants.md").read_text()
    sections = re.findall(r"`python -m baselines\.evaluate --env-id (\S+)`:\n\n```\n(.*?)```",
                          text, flags=re.S)
    assert {env_id for env_id, _ in sections} == {"ACLDBeamLab-v1", "ACLDBeamHard-v1"}
    for env_id, table in sections:
        assert main(["--env-id", env_id, "--quiet"]) == 0
        assert _rows(capsys.readouterr().out) == _rows(table), env_id
