"""The generated blocks of the Markdown pages (the training page's tables, the README's
headline): their markers, rendering and replacement (:func:`render_blocks`,
:func:`write_blocks`)."""

from __future__ import annotations

from .report_tables import headline, markdown

__all__ = ["BLOCKS", "MARK_BEGIN", "MARK_END", "replace_block", "render_blocks", "write_blocks"]


#: The generated blocks a Markdown page may hold (``--write``), by kind: the full tables
#: (:func:`markdown`, the training page) and the headline (:func:`headline`, the README).
BLOCKS = {"tables": markdown, "headline": headline}

#: The markers around a generated block (``kind`` one of :data:`BLOCKS`).
MARK_BEGIN = "<!-- benchmark-{kind}:begin (python -m train.core.report {src} --write {dst}) -->"
MARK_END = "<!-- benchmark-{kind}:end -->"


def replace_block(text: str, tables: str, src: str, dst: str, kind: str = "tables") -> str:
    """``text`` with the part between the markers of ``kind`` (:data:`MARK_BEGIN`,
    :data:`MARK_END`) replaced by ``tables``; ``ValueError`` if the markers are missing."""
    begin, end = MARK_BEGIN.format(kind=kind, src=src, dst=dst), MARK_END.format(kind=kind)
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        raise ValueError(f"{dst}: expected one {begin!r} ... {end!r} block")
    head, rest = text.split(begin)
    _, tail = rest.split(end)
    return f"{head}{begin}\n\n{tables}\n{end}{tail}"


def render_blocks(summary: dict) -> dict[str, str]:
    """Every generated block (:data:`BLOCKS`) of ``summary``, by kind."""
    return {kind: render(summary) for kind, render in BLOCKS.items()}


def write_blocks(text: str, blocks: dict[str, str], src: str, dst: str) -> str:
    """``text`` with every generated block it holds (each once) replaced by its rendered
    ``blocks`` (:func:`render_blocks`); ``ValueError`` if it holds none."""
    kinds = [k for k in blocks if MARK_END.format(kind=k) in text]
    if not kinds:
        begins = " or ".join(repr(MARK_BEGIN.format(kind=k, src=src, dst=dst)) for k in blocks)
        raise ValueError(f"{dst}: expected one {begins} block")
    for kind in kinds:
        text = replace_block(text, blocks[kind], src, dst, kind)
    return text
