"""Sphinx roles and numpydoc entry lines rewritten as Markdown, for the docs build only.

The package's docstrings are reStructuredText (numpydoc, Sphinx roles): the command-line
help strips the roles (:mod:`acld_gym.util.text`), and this module turns them into
mkdocstrings autorefs when the site is built (:mod:`sphinx_roles` is the griffe extension).
Nothing here imports the package: a resolver callable maps a role's target to an object's
full path, or to None when the target is not an object of the site.
"""

from __future__ import annotations

import re
from collections.abc import Callable

Resolver = Callable[[str], "str | None"]

#: ``:class:`x```, ``:py:func:`~a.b```, ``:math:`x^2``` (content: no backtick).
ROLE = re.compile(r":(?:py:)?(?P<role>[a-z]+):`(?P<content>[^`]+)`")
#: the roles that name a Python object
OBJECT_ROLES = frozenset({"class", "func", "meth", "mod", "data", "attr", "obj", "exc", "const"})
#: RST inline literal ``x``; the content holds no backtick
LITERAL = re.compile(r"``(?P<content>[^`]+?)``")
#: an explicit title, ``title <target>``
TITLED = re.compile(r"^(?P<title>.*?)\s*<(?P<target>[^<>]+)>$")
#: an RST literal (ends at ``\`\``` not followed by a backtick, so it may hold single
#: backticks), a role, or a code span already in Markdown form
INLINE = re.compile(
    r"``(?P<lit>[^`\s](?:.*?[^\s])??)``(?!`)"
    r"|:(?:py:)?(?P<role>[a-z]+):`(?P<content>[^`]+)`"
    r"|`[^`]+`",
    re.S,
)
FENCE = re.compile(r"^\s*(```|~~~)")

SECTIONS_WITH_TYPES = {
    "parameters": "param",
    "other parameters": "param",
    "attributes": "param",
    "returns": "return",
    "yields": "return",
    "receives": "return",
}
# Words a numpydoc type is made of; a "type" with several other words is a description.
TYPE_WORDS = frozenset(
    "of or and optional default none shape array array_like ndarray int float bool str complex "
    "tuple list dict sequence callable iterable mapping path bytes object any dtype same length "
    "instance subclass each per one two the a an in to keyword only positional".split()
)
_IDENT = re.compile(r"^\*{0,2}[A-Za-z_][A-Za-z0-9_]*$")


def split_target(content: str) -> tuple[str, str, bool]:
    """Return ``(display, target, linkable)`` of a role's content.

    ``~a.b.c`` shows ``c``; ``title <a.b>`` shows the title; ``!a.b`` is not linked; a
    trailing ``()`` stays in the display but not the target.
    """
    content = " ".join(content.split())
    titled = TITLED.match(content)
    if titled and titled["title"]:
        display, target = titled["title"], titled["target"].replace(" ", "")
    else:
        display, target = None, content.replace(" ", "")
    linkable = not target.startswith("!")
    target = target.lstrip("!")
    short = target.startswith("~")
    target = target.lstrip("~")
    if display is None:
        display = target.rsplit(".", 1)[-1] if short else target
    target = target.removesuffix("()")
    return display, target, linkable


def code(text: str) -> str:
    """``text`` as a Markdown code span (longer fences when it holds backticks)."""
    if "`" not in text:
        return f"`{text}`"
    return f"`` {text} ``"


def math_inline(tex: str) -> str:
    """Inline LaTeX for pymdownx.arithmatex (``\\( ... \\)``, rendered by MathJax on the site)."""
    return f"\\({' '.join(tex.split())}\\)"


def math_block(tex_lines: list[str], indent: str) -> list[str]:
    """A display formula for pymdownx.arithmatex: ``\\[``, the expression, ``\\]``, each on a line
    of its own at ``indent`` rounded down to a multiple of 4 (Markdown's nesting step: the
    formula's block is found only at its container's own indentation, and a directive
    indented 2 under a list item's text is a paragraph after the list), a blank line
    before and after."""
    indent = " " * (len(indent.expandtabs(4)) // 4 * 4)
    body = [line.strip() for line in tex_lines if line.strip()]
    return ["", f"{indent}\\[", *(f"{indent}{line}" for line in body), f"{indent}\\]", ""]


def role_markdown(role: str, content: str, resolve: Resolver) -> str:
    """The Markdown for one role: an autoref when the target resolves, else code."""
    if role == "math":
        return math_inline(content)
    if role not in OBJECT_ROLES:
        return code(content.strip())
    display, target, linkable = split_target(content)
    path = resolve(target) if linkable and target else None
    if path is None:
        return code(display)
    return f"[{code(display)}][{path}]"


def role_plain(content: str) -> str:
    """A role in a type position: the plain (short) name, for griffe to parse and link."""
    display, target, _ = split_target(content)
    return target if display == target else display


def _inline(line: str, resolve: Resolver) -> str:
    # one left-to-right pass: a literal's content (which may hold a role) is never a role
    def convert(match: re.Match) -> str:
        if match["lit"] is not None:
            return code(match["lit"])
        if match["role"] is not None:
            return role_markdown(match["role"], match["content"], resolve)
        return match[0]

    return INLINE.sub(convert, line)


#: A dotted Python path (``gymnasium.spaces.Box``): a type, whatever its lowercase parts.
DOTTED = re.compile(r"\b[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)+\b")


def _is_description(text: str) -> bool:
    """True when a numpydoc 'type' reads as a sentence rather than a type."""
    plain = ROLE.sub(lambda m: role_plain(m["content"]), text)
    plain = LITERAL.sub(lambda m: m["content"], plain).strip()
    if not plain:
        return False
    if plain.endswith(".") and not plain.endswith("..."):
        return True
    plain = DOTTED.sub(" ", plain)  # gymnasium.vector.VectorEnv: one type, not two words
    words = re.findall(r"[A-Za-z][A-Za-z_'-]*", re.sub(r"\([^)]*\)|\[[^\]]*\]", " ", plain))
    prose = [w for w in words if w.islower() and len(w) > 1 and w not in TYPE_WORDS]
    return len(prose) >= 2


def _entry(line: str, kind: str, indent: str) -> list[str] | None:
    """A ``names : text`` line whose text is a description, rewritten (else None)."""
    body = line[len(indent) :]
    if " : " not in body:
        if kind == "return" and _is_description(body):
            return [f"{indent}:", f"{indent}    {body.strip()}"]
        return None
    names, _, rest = body.partition(" : ")
    if not _is_description(rest):
        return None
    names = names.strip()
    single = all(_IDENT.match(n.strip()) for n in names.split(","))
    if kind == "param" and single:
        return [f"{indent}{names}", f"{indent}    {rest.strip()}"]
    if kind == "return" and _IDENT.match(names):
        return [f"{indent}{names} :", f"{indent}    {rest.strip()}"]
    # several names in Returns, or names griffe cannot read: the names join the text
    return [f"{indent}:", f"{indent}    {code(names)}: {rest.strip()}"]


def _fix_types(line: str, kind: str) -> str:
    """In a ``names : type`` line, roles become plain names and literals lose backticks."""
    names, sep, rest = line.partition(" : ")
    if not sep and kind == "return":  # a Returns line without a name is all type
        names, sep, rest = "", "", line
    rest = ROLE.sub(lambda m: role_plain(m["content"]), rest)
    rest = LITERAL.sub(lambda m: m["content"], rest)
    return names + sep + rest


#: A Markdown table row whose cells before the last are empty: the last cell continues the
#: row above (the docstrings wrap a long cell so, for a terminal's ``help()``).
CONTINUED_ROW = re.compile(r"^(\s*)\|(?:\s*\|)+\s*(?P<text>[^|]*?)\s*\|\s*$")


def merge_continued_rows(lines: list[str]) -> list[str]:
    """Table rows that continue the row above (:data:`CONTINUED_ROW`) joined into it, so a
    wrapped cell renders as one cell and not as rows of empty cells."""
    out: list[str] = []
    for line in lines:
        m = CONTINUED_ROW.match(line)
        prev = out[-1].rstrip() if out else ""
        if m and prev.startswith(line[: len(m.group(1))] + "|") and prev.endswith("|"):
            if not CONTINUED_ROW.match(prev) and set(prev.replace("|", "").strip()) <= set("-: "):
                out.append(line)  # the row after the header's separator: a row of its own
                continue
            out[-1] = prev[:-1].rstrip() + " " + m.group("text") + " |"
            continue
        out.append(line)
    return out


def rewrite(text: str, resolve: Resolver) -> str:
    """A numpydoc docstring with its roles as autorefs or code, ready for mkdocstrings.

    Fenced code blocks, doctest lines (``>>>``, ``...`` and their output) and RST literal
    blocks (the indented lines after a line ending in ``::``) are left as they are.
    Entries of the typed sections (Parameters, Returns, ...) whose "type" is a sentence
    are rewritten so the sentence lands in the description; a table's wrapped cells are
    joined (:func:`merge_continued_rows`).
    """
    lines = merge_continued_rows(text.split("\n"))
    out: list[tuple[bool, str]] = []  # (prose, line)
    fence: str | None = None
    doctest = False
    literal_indent: int | None = None
    math: tuple[int, str, list[str]] | None = None  # an open .. math:: block
    section: str | None = None
    section_indent = ""
    for i, line in enumerate(lines):
        stripped = line.strip()
        indent_len = len(line) - len(line.lstrip())
        if fence is not None:
            out.append((False, line))
            if stripped.startswith(fence):
                fence = None
            continue
        if (opened := FENCE.match(line)) is not None:
            fence = opened[1]
            out.append((False, line))
            continue
        if math is not None:
            if not stripped or indent_len > math[0]:
                math[2].append(line)
                continue
            out.extend((False, m) for m in math_block(math[2], math[1]))
            math = None
        if literal_indent is not None:
            if not stripped or indent_len > literal_indent:
                out.append((False, line))
                continue
            literal_indent = None
        if stripped.startswith(">>>"):
            doctest = True
        elif not stripped:
            doctest = False
        if doctest:
            out.append((False, line))
            continue
        # numpydoc section header: a title line underlined by dashes
        nxt = lines[i + 1].strip() if i + 1 < len(lines) else ""
        if stripped and nxt and set(nxt) == {"-"} and len(nxt) >= 3:
            section = SECTIONS_WITH_TYPES.get(stripped.lower())
            section_indent = line[:indent_len]
        elif section and stripped and indent_len == len(section_indent) and set(stripped) != {"-"}:
            fixed = _entry(line, section, section_indent)
            if fixed is not None:
                out.extend((True, f) for f in fixed)
                continue
            out.append((False, _fix_types(line, section)))
            continue
        if stripped.startswith(".. math::"):
            # the display math directive: its lines (the first's rest, then the deeper ones)
            # as one display formula
            math = (indent_len, line[:indent_len], [stripped.removeprefix(".. math::")])
            continue
        if stripped.endswith("::") and not stripped.startswith(".."):
            literal_indent = indent_len
            line = line[: line.rstrip().rfind("::")] + (":" if stripped != "::" else "")
        out.append((bool(stripped), line))
    if math is not None:
        out.extend((False, m) for m in math_block(math[2], math[1]))
    # roles and literals may run over a line break: convert each run of prose lines at once
    result: list[str] = []
    run: list[str] = []
    for prose, line in [*out, (False, None)]:
        if prose:
            run.append(line)
            continue
        if run:
            result.extend(_inline("\n".join(run), resolve).split("\n"))
            run = []
        if line is not None:
            result.append(line)
    return "\n".join(result)
