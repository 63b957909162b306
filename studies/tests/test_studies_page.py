"""The research record's page, ``studies/studies.md`` (``docs/studies.md`` until it left the
documentation site): its ```python blocks run and every value they claim is what they
print, by the rules of the docs pages (:mod:`tests.doc_blocks`, as in
:mod:`tests.test_docs`); and its links, which no docs build checks any more, reach a file
of the checkout and a heading of that file."""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path

from tests.doc_blocks import claims, python_blocks, run_page

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "studies" / "studies.md"
#: A markdown link to a relative target, ``[text](path#anchor)``.
LINK = re.compile(r"\]\(([^)\s:]+)\)")


def slug(heading: str) -> str:
    """A heading's anchor as the docs build makes it (Python-Markdown's ``toc`` slugify)."""
    text = unicodedata.normalize("NFKD", heading).encode("ascii", "ignore").decode()
    return re.sub(r"[-\s]+", "-", re.sub(r"[^\w\s-]", "", text).strip().lower())


def anchors(page: Path) -> set[str]:
    """The anchors of a page's headings (outside code blocks)."""
    text = re.sub(r"^```.*?^```", "", page.read_text(), flags=re.S | re.M)
    return {slug(h) for h in re.findall(r"^#{1,6} (.+?)\s*$", text, flags=re.M)}


def test_the_page_is_out_of_the_site():
    """The page is here and not among the docs pages (nor in the site's navigation)."""
    assert PAGE.is_file() and not (ROOT / "docs" / "studies.md").exists()
    assert "studies.md" not in (ROOT / "mkdocs.yml").read_text()


def test_python_blocks_run_and_claims_hold(monkeypatch):
    monkeypatch.chdir(ROOT)  # paths in the page are the checkout's
    text = PAGE.read_text()
    blocks = python_blocks(text)
    assert len(blocks) >= 4 and sum(len(claims(block)) for block in blocks) >= 7
    assert run_page(text, {"__name__": "__docs__"}, "studies/studies.md") == []


def test_slug_is_the_docs_builds():
    assert slug("Every client's runs, release by release") == (
        "every-clients-runs-release-by-release"
    )
    assert slug("The SAC recipe, one piece at a time") == "the-sac-recipe-one-piece-at-a-time"
    assert slug("Training bit for bit on one kind of CPU") == (
        "training-bit-for-bit-on-one-kind-of-cpu"
    )


def test_links_reach_a_file_and_a_heading():
    links = LINK.findall(PAGE.read_text())
    assert len(links) >= 10
    bad = []
    for link in links:
        path, _, anchor = link.partition("#")
        target = (PAGE.parent / path).resolve() if path else PAGE
        if not target.is_file():
            bad.append(f"{link}: no file {target}")
        elif anchor and anchor not in anchors(target):
            bad.append(f"{link}: no heading #{anchor} in {target.name}")
    assert bad == []
