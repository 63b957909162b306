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


def _rows(text: str, score: bool = False) -> list[list[str]]:
    """The policy rows of the evaluation tables (``score``: of the score table that follows
    them), without the ms/step column of the case tables."""
    cases, _, scores = text.partition("\nscore on ")
    rows = [line.split() for line in (scores if score else cases).splitlines()
            if re.match(r"^\s+(passive|lqr|smc|mpc|bound)\s", line)]
    return [r[:-1] if len(r) == 9 else r for r in rows]  # (9 columns: a row with ms/step)


def _sections() -> list[tuple[str, str]]:
    text = (DOCS / "variants.md").read_text()
    sections = re.findall(r"`python -m baselines\.evaluate --env-id (\S+)`:\n\n```\n(.*?)```",
                          text, flags=re.S)
    assert {env_id for env_id, _ in sections} == {"ACLDBeamLab-v1", "ACLDBeamHard-v1"}
    return sections


def test_variant_tables_are_what_their_commands_print(capsys):
    """The case tables (with the effort lines); the score is the slow test's."""
    from baselines.evaluate import main

    for env_id, table in _sections():
        assert "\nscore on " in table, env_id  # the page shows the score too
        assert main(["--env-id", env_id, "--score-episodes", "0", "--quiet"]) == 0
        assert _rows(capsys.readouterr().out) == _rows(table), env_id


@pytest.mark.slow
def test_variant_scores_are_what_their_commands_print(capsys):
    """The whole output of each command, the score on the 100 test episodes included."""
    from baselines.evaluate import main

    for env_id, table in _sections():
        assert main(["--env-id", env_id, "--quiet"]) == 0
        out = capsys.readouterr().out
        assert _rows(out) == _rows(table), env_id
        assert _rows(out, score=True) == _rows(table, score=True) != [], env_id
