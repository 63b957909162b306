"""Griffe extension: the docstrings' Sphinx roles become mkdocstrings autorefs at build time.

Loaded by mkdocs.yml (``plugins.mkdocstrings.handlers.python.options.extensions``) with the
first-party packages as its option; the docstrings in the source stay reStructuredText.
When every listed package is loaded, each object's docstring is rewritten by
:func:`rst_to_md.rewrite`: a role whose target is a public object of those packages becomes
``[`name`][full.path]``; any other target (external, private, unknown) becomes code, so a
stale name never breaks the strict build.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import Any

from griffe import Alias, Docstring, Extension, GriffeLoader, Module, Object

sys.path.insert(0, str(Path(__file__).resolve().parent))
from rst_to_md import rewrite  # noqa: E402

_log = logging.getLogger("mkdocs.plugins.griffe_ext.sphinx_roles")
_DONE = "sphinx_roles_done"


def _public(path: str) -> bool:
    return not any(part.startswith("_") for part in path.split("."))


def _rendered(obj: Object) -> bool:
    # mkdocstrings shows an object without a docstring only as a module (show_if_no_docstring)
    while obj is not None and not obj.is_module:
        if not obj.docstring:
            return False
        obj = obj.parent
    return True


def _comment_docstrings(obj: Object, loader: GriffeLoader) -> None:
    """Attributes documented by ``#:`` comments above them (Sphinx's form) get that text."""
    for member in obj.members.values():
        if member.is_alias:
            continue
        if member.is_attribute and member.docstring is None and member.lineno:
            try:
                lines = member.lines_collection[member.filepath]
            except (KeyError, TypeError):
                lines = []
            comment: list[str] = []
            row = member.lineno - 2
            while 0 <= row < len(lines) and lines[row].strip().startswith("#:"):
                comment.insert(0, lines[row].strip()[2:].strip())
                row -= 1
            if comment:
                member.docstring = Docstring(
                    "\n".join(comment),
                    lineno=row + 2,
                    endlineno=member.lineno - 1,
                    parent=member,
                    parser=loader.docstring_parser,
                    parser_options=loader.docstring_options,
                )
        if member.is_module or member.is_class:
            _comment_docstrings(member, loader)


class SiteIndex:
    """Resolves role targets against the loaded packages (canonical, public paths only)."""

    def __init__(self, collection: Any, packages: list[str], owners: list[str] = ()) -> None:
        self.collection = collection
        self.packages = packages
        self.owners = tuple(owners)
        self.paths: list[str] = []
        for name in packages:
            self._walk(collection[name])

    def _walk(self, obj: Object) -> None:
        self.paths.append(obj.path)
        for member in obj.members.values():
            if not member.is_alias:
                self._walk(member)

    def canonical(self, path: str) -> str | None:
        """The defining path of ``path`` if it names a public object of the packages."""
        for _ in range(8):
            try:
                obj = self.collection.get_member(path)
            except Exception:  # noqa: BLE001 - any lookup failure means "not ours"
                return None
            if isinstance(obj, Alias):
                path = obj.target_path
                continue
            if obj.path.split(".")[0] not in self.packages or not _public(obj.path):
                return None
            if not _rendered(obj):
                return None
            # a member of a class rendered without its members links to the class
            owner = next((o for o in self.owners if obj.path.startswith(f"{o}.")), None)
            return owner or obj.path
        return None

    def resolve(self, target: str, obj: Object) -> str | None:
        """``target`` as written in ``obj``'s docstring, as a full path (or None)."""
        target = target.lstrip(".")
        if not target or not all(part.isidentifier() for part in target.split(".")):
            return None
        candidates = []
        if target.split(".")[0] in self.packages:
            candidates.append(target)
        scope: Object | None = obj
        while scope is not None:
            candidates.append(f"{scope.path}.{target}")
            scope = scope.parent
        candidates += [f"{name}.{target}" for name in self.packages]
        for candidate in candidates:
            if (path := self.canonical(candidate)) is not None:
                return path
        ends = {self.canonical(p) for p in self.paths if p.endswith(f".{target}")} - {None}
        return ends.pop() if len(ends) == 1 else None


class SphinxRoles(Extension):
    """Rewrites every docstring of ``packages`` once all of them are loaded.

    Parameters
    ----------
    packages
        The first-party packages: role targets resolve among their public objects.
    owners
        Classes the site renders without their members (``members: false``): a role
        naming one of their members links to the class.
    """

    def __init__(self, packages: list[str] | None = None, owners: list[str] | None = None) -> None:
        super().__init__()
        self.packages = list(packages or [])
        self.owners = list(owners or [])
        self.links = 0
        self.codes = 0

    def on_package(self, *, pkg: Module, loader: GriffeLoader, **kwargs: Any) -> None:
        """Load the other listed packages, then rewrite all of them (once)."""
        if pkg.name not in self.packages:
            return
        collection = loader.modules_collection
        for name in self.packages:
            if name not in collection:
                loader.load(name, try_relative_path=False)
        if not all(name in collection for name in self.packages):
            return  # a nested load finishes the job
        for name in self.packages:
            _comment_docstrings(collection[name], loader)
        index = SiteIndex(collection, self.packages, self.owners)
        before = (self.links, self.codes)
        for name in self.packages:
            self._rewrite_tree(collection[name], index)
        if (self.links, self.codes) != before:
            links, codes = self.links - before[0], self.codes - before[1]
            _log.info("sphinx_roles: %d roles linked, %d rendered as code", links, codes)

    def _rewrite_tree(self, obj: Object, index: SiteIndex) -> None:
        if obj.extra.get("griffe_ext", {}).get(_DONE):
            return
        obj.extra.setdefault("griffe_ext", {})[_DONE] = True
        if obj.docstring is not None:

            def resolve(target: str, owner: Object = obj) -> str | None:
                path = index.resolve(target, owner)
                if path is None:
                    self.codes += 1
                    _log.debug("%s: no public object for %r, rendered as code", owner.path, target)
                else:
                    self.links += 1
                return path

            obj.docstring.value = rewrite(obj.docstring.value, resolve)
        for member in obj.members.values():
            if not member.is_alias:
                self._rewrite_tree(member, index)
