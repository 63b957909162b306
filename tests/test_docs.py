"""The documentation pages under ``docs/``: every ```python block runs and every value it
claims is what it prints (the README's rules, :mod:`tests.doc_blocks`), and each reference
table of ``python -m baselines.evaluate --env-id ID`` (``docs/baselines.md``,
``docs/variants.md``) is what its command prints today (all columns but the timings)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.doc_blocks import python_blocks, run_page

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = sorted(DOCS.rglob("*.md"))
#: The pages whose evaluation tables are checked against their command.
TABLE_PAGES = ("baselines.md", "variants.md")


def test_the_pages_have_code():
    """The blocks are found (the README's quick start, included by a snippet, runs in
    :mod:`tests.test_readme`)."""
    start = (DOCS / "getting-started.md").read_text()
    assert len(python_blocks(start)) >= 5 and '--8<-- "README.md:quickstart"' in start
    assert len(python_blocks((DOCS / "variants.md").read_text())) >= 1


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(DOCS)))
def test_python_blocks_run_and_claims_hold(page, monkeypatch):
    monkeypatch.chdir(DOCS.parent)  # paths in the pages are the checkout's
    assert run_page(page.read_text(), {"__name__": "__docs__"}, str(page.relative_to(DOCS))) == []


def _rows(text: str, score: bool = False) -> list[list[str]]:
    """The policy rows of the evaluation tables (``score``: of the score table that follows
    them), without the ms/step column of the case tables."""
    cases, _, scores = text.partition("\nscore on ")
    rows = [line.split() for line in (scores if score else cases).splitlines()
            if re.match(r"^\s+(passive|lqr|smc|mpc|bound)\s", line)]
    return [r[:-1] if len(r) == 9 else r for r in rows]  # (9 columns: a row with ms/step)


def _sections() -> list[tuple[str, str]]:
    text = "\n".join((DOCS / page).read_text() for page in TABLE_PAGES)
    sections = re.findall(r"`python -m baselines\.evaluate --env-id (\S+)`:\n\n```\n(.*?)```",
                          text, flags=re.S)
    assert [env_id for env_id, _ in sections] == ["ACLDBeam-v1", "ACLDBeamLab-v1",
                                                   "ACLDBeamHard-v1"]
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
