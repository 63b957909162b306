"""The words a command shows: its help in plain text and the name it was called by.

The package's command-line tools take their help from module docstrings, written in
reStructuredText for the API reference. :func:`plain` turns such a docstring into text for
a terminal: Sphinx roles become the name they point to, literals lose their backticks,
math becomes readable (``:math:`\\hat x^+``` -> ``x̂⁺``), a ``.. math::`` block keeps its
lines, ``Examples::`` keeps its example block, and paragraphs and list items are filled to
the terminal's width. :func:`prog` is the program name a parser shows: ``acld-gym SUB``
when the ``acld-gym`` command runs the tool (:func:`invoked_as`), else the tool's own
``python -m`` form; run that way, :func:`plain` also names every tool the text mentions by
its ``acld-gym`` command (``python -m train.ship`` -> ``acld-gym ship``), so a help text
speaks of one command line.
"""

from __future__ import annotations

import inspect
import re
import shutil
import textwrap
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

__all__ = ["plain", "math_text", "prog", "invoked_as", "command_names"]

_INVOKED_AS: ContextVar[str | None] = ContextVar("acld_gym_invoked_as", default=None)
#: ``python -m`` forms -> ``acld-gym`` commands, while the ``acld-gym`` command runs a tool.
_COMMAND_NAMES: ContextVar[dict[str, str] | None] = ContextVar(
    "acld_gym_command_names", default=None
)

#: LaTeX commands of one argument that only style it.
_STYLES = r"mathrm|text|operatorname|mathbf|boldsymbol|mathit|mathcal|mathsf|rm|bf"
_GREEK = (
    "alpha beta gamma delta epsilon zeta eta theta iota kappa lambda mu nu xi pi rho "
    "sigma tau upsilon phi chi psi omega"
).split()
_SYMBOLS = {
    **dict(zip(_GREEK, "αβγδεζηθικλμνξπρστυφχψω", strict=True)),
    "varepsilon": "ε",
    "varphi": "φ",
    "Gamma": "Γ",
    "Delta": "Δ",
    "Theta": "Θ",
    "Lambda": "Λ",
    "Pi": "Π",
    "Sigma": "Σ",
    "Phi": "Φ",
    "Psi": "Ψ",
    "Omega": "Ω",
    "pm": "±",
    "mp": "∓",
    "times": "×",
    "cdot": "·",
    "le": "≤",
    "leq": "≤",
    "ge": "≥",
    "geq": "≥",
    "ne": "≠",
    "neq": "≠",
    "approx": "≈",
    "sim": "~",
    "propto": "∝",
    "infty": "∞",
    "to": "→",
    "rightarrow": "→",
    "in": "∈",
    "sum": "Σ",
    "prod": "Π",
    "int": "∫",
    "partial": "∂",
    "nabla": "∇",
    "sqrt": "√",
    "dots": "…",
    "ldots": "…",
    "cdots": "…",
    "lVert": "‖",
    "rVert": "‖",
    "|": "‖",
    "lvert": "|",
    "rvert": "|",
    "quad": "  ",
    "qquad": "    ",
    ",": " ",
    ";": " ",
    ":": " ",
    "!": "",
    "left": "",
    "right": "",
    "max": "max",
    "min": "min",
    "log": "log",
    "exp": "exp",
}
#: Accents (LaTeX command names) and the combining mark each puts on its argument.
_ACCENTS = {"hat|widehat": "\u0302", "bar|overline": "\u0304", "dot": "\u0307"}
_SUPERSCRIPTS = str.maketrans("0123456789+-=()nT", "⁰¹²³⁴⁵⁶⁷⁸⁹⁺⁻⁼⁽⁾ⁿᵀ")
#: Stands for a space that filling must not break at (short literals), and their length limit.
_KEEP, _KEEP_UP_TO = "\x00", 60
_ROLE = re.compile(r":(?:[A-Za-z][\w-]*:)+`([^`]+)`")
_MATH_ROLE = re.compile(r":math:`([^`]+)`")
_DIRECTIVE = re.compile(r"^(\s*)\.\.\s+([\w-]+)::\s*(.*)$")
_BULLET = re.compile(r"^(\s*)([*+-]|\d+[.)]|#\.)\s+")


def _script(body: str, mark: str) -> str:
    """A super- (``^``) or subscript (``_``) readable on one line."""
    if mark == "^" and body and all(c in "0123456789+-=()nT" for c in body):
        return body.translate(_SUPERSCRIPTS)
    return f"{mark}{body}" if len(body) == 1 else f"{mark}({body})"


def math_text(tex: str) -> str:
    """LaTeX math as plain text: ``\\hat x`` -> ``x̂``, Greek letters and common symbols as
    their characters, ``^{-1}`` -> ``⁻¹``, other scripts as ``^(...)`` / ``_(...)``,
    styling commands and alignment marks (``&``, ``\\\\``) dropped."""
    s = tex.replace("\\\\", " ").replace("&", "")
    s = re.sub(rf"\\(?:{_STYLES})\s*\{{([^{{}}]*)\}}", r"\1", s)
    s = re.sub(r"\\frac\s*\{([^{}]*)\}\s*\{([^{}]*)\}", r"(\1)/(\2)", s)
    for accent, mark in _ACCENTS.items():  # x with a combining mark: \hat x -> x̂
        s = re.sub(
            rf"\\(?:{accent})\s*(?:\{{([^{{}}]*)\}}|(\w))",
            lambda m, mark=mark: (m[1] or m[2]) + mark,
            s,
        )
    s = re.sub(r"\\([A-Za-z]+|[,;:!|])", lambda m: _SYMBOLS.get(m[1], m[1]), s)
    s = re.sub(r"([\^_])\s*\{([^{}]*)\}", lambda m: _script(m[2].strip(), m[1]), s)
    s = re.sub(r"\^([0-9+\-nT])", lambda m: _script(m[1], "^"), s)
    s = s.replace("{", "").replace("}", "")
    return re.sub(r"[ \t]+", " ", s).strip()


def _role(match: re.Match) -> str:
    """The text a Sphinx role shows: ``title <target>`` -> title, ``~a.b`` -> b, ``!a`` -> a."""
    text = match[1].strip()
    titled = re.fullmatch(r"(.*?)\s*<([^<>]+)>", text, re.S)
    if titled and titled[1]:
        return titled[1]
    text = titled[2] if titled else text
    if text.startswith("~"):
        return text[1:].rsplit(".", 1)[-1]
    return text.lstrip("!")


def _literal(match: re.Match) -> str:
    """A double-backtick literal's text; a short one (a command, an expression) held on one
    line when filled (:data:`_KEEP` for its spaces, made spaces again by :func:`plain`)."""
    text = " ".join(match[1].split())
    return text.replace(" ", _KEEP) if len(text) <= _KEEP_UP_TO else text


def _inline(text: str) -> str:
    """Inline reStructuredText as plain text (roles, literals, emphasis, interpreted text)."""
    text = _MATH_ROLE.sub(lambda m: math_text(m[1]), text)
    text = _ROLE.sub(_role, text)
    text = re.sub(r"``(.+?)``", _literal, text, flags=re.S)
    text = re.sub(r"(?<![\w`])`([^`]+)`_{0,2}(?![\w`])", r"\1", text)
    text = re.sub(r"(?<![\w*])\*\*(\S(?:.*?\S)?)\*\*(?![\w*])", r"\1", text, flags=re.S)
    text = re.sub(r"(?<![\w*])\*(\S(?:[^*]*?\S)?)\*(?![\w*])", r"\1", text, flags=re.S)
    return text


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def _fill(text: str, width: int, first: str, rest: str) -> str:
    """``text`` filled to ``width``, each short literal on one line unless one is longer
    than a line (then it breaks at its spaces too)."""
    for kept in (text, text.replace(_KEEP, " ")):
        filled = textwrap.fill(
            " ".join(kept.split()),
            width,
            initial_indent=first,
            subsequent_indent=rest,
            break_long_words=False,
            break_on_hyphens=False,
        )
        if all(len(line) <= width for line in filled.split("\n")):
            break
    return filled


def _prose(lines: list[str], width: int) -> str:
    """One block of prose: list items filled with a hanging indent, a paragraph of one
    indentation filled, anything else (a definition list, a table) kept line by line."""
    text = _inline("\n".join(lines)).split("\n")
    base = min(_indent(line) for line in text)
    if all(_BULLET.match(line) is None for line in text) or _BULLET.match(text[0]) is None:
        if len({_indent(line) for line in text}) == 1:
            return _fill(" ".join(text), width, " " * base, " " * base)
        return "\n".join(text)
    items: list[list[str]] = []
    for line in text:
        bullet = _BULLET.match(line)
        if bullet is not None and _indent(line) == base:
            items.append([line])
        else:
            items[-1].append(line)
    out = []
    for item in items:
        bullet = _BULLET.match(item[0])
        head = f"{bullet[1]}{bullet[2]} "
        body = " ".join([item[0][bullet.end() :], *item[1:]])
        out.append(_fill(body, width, head, " " * len(head)))
    return "\n".join(out)


def _blocks(doc: str) -> Iterator[list[str]]:
    """The blank-line separated blocks of ``doc`` (as lists of lines)."""
    block: list[str] = []
    for line in doc.split("\n"):
        if line.strip():
            block.append(line.rstrip())
        elif block:
            yield block
            block = []
    if block:
        yield block


def plain(doc: str | None, width: int | None = None) -> str:
    """A reStructuredText docstring as plain text for a terminal (see the module's text).

    Parameters
    ----------
    doc : str or None
        The docstring (``None``: an empty text).
    width : int, optional
        The line width to fill prose to; default the terminal's width less 2, at most 100
        (as argparse fills its help).

    Returns
    -------
    str
        The text, blocks separated by a blank line, for an argparse description or epilog
        with ``RawDescriptionHelpFormatter`` (which keeps the lines as they are).
    """
    if not doc:
        return ""
    if width is None:
        width = max(40, min(100, shutil.get_terminal_size().columns - 2))
    out: list[str] = []
    literal_at: int | None = None  # the indentation a literal block must exceed
    math_at: int | None = None
    for block in _blocks(inspect.cleandoc(doc)):
        indent = _indent(block[0])
        if literal_at is not None and indent > literal_at:
            out.append("\n".join(block))  # a literal block: as written
            continue
        if math_at is not None and indent > math_at:
            out.append("\n".join(" " * indent + math_text(line) for line in block))
            continue
        literal_at = math_at = None
        directive = _DIRECTIVE.match(block[0])
        if directive is not None:
            lead, name, arg = directive.groups()
            if name == "math":
                math_at = len(lead)
                rest = [arg, *(line.strip() for line in block[1:])]
                if any(rest):
                    out.append(f"{lead}    " + math_text(" ".join(rest)))
                continue
            block = [f"{lead}{name.capitalize()}: {arg}".rstrip(), *block[1:]]
        if block[-1].endswith("::"):
            literal_at = indent
            end = block[-1][:-2]
            block[-1] = end.rstrip() if end.endswith((" ", "\t")) or not end.strip() else end + ":"
            block = [line for line in block if line.strip()]
            if not block:
                continue
        out.append(_prose(block, width))
    return command_names("\n\n".join(out).replace(_KEEP, " "))


def prog(default: str) -> str:
    """The program name a command's parser shows: ``acld-gym SUB`` when the ``acld-gym``
    command runs it (inside :func:`invoked_as`), else ``default`` (its ``python -m`` form)."""
    return _INVOKED_AS.get() or default


def command_names(text: str) -> str:
    """``text`` with each ``python -m MODULE`` that the running ``acld-gym`` command knows
    as a subcommand written as that command (:func:`invoked_as`'s ``names``); unchanged
    outside it. ``python -m train`` is not ``python -m train.ship``: a module name ends where
    no letter, digit, ``_`` or ``.`` followed by one comes next."""
    names = _COMMAND_NAMES.get()
    if not names:
        return text
    pattern = "|".join(re.escape(m) for m in sorted(names, key=len, reverse=True))
    found = re.compile(rf"python -m ({pattern})(?![\w]|\.\w)")
    return found.sub(lambda m: names[m.group(1)], text)


@contextmanager
def invoked_as(name: str, names: dict[str, str] | None = None) -> Iterator[None]:
    """Within the block, :func:`prog` returns ``name`` (the ``acld-gym`` command's
    subcommand, e.g. ``"acld-gym evaluate"``) and :func:`plain` writes the modules of
    ``names`` (``{"train.ship": "acld-gym ship", ...}``) as their commands; without
    ``names``, an enclosing block's stay (a command that runs another's ``main``)."""
    token = _INVOKED_AS.set(name)
    names_token = _COMMAND_NAMES.set(dict(names) if names else _COMMAND_NAMES.get())
    try:
        yield
    finally:
        _COMMAND_NAMES.reset(names_token)
        _INVOKED_AS.reset(token)
