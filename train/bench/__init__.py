"""Deprecated: the training core is :mod:`train.core` (renamed in acld-gym 0.21.0).

``train.bench`` and its submodules (``train.bench.evaluate``, ``train.bench.trials``, ...)
are the modules of :mod:`train.core` under their old names, for one more version: importing
one warns once (a ``DeprecationWarning`` naming the new path) and gives the very module
object of ``train.core``; ``python -m train.bench.report`` still runs
``python -m train.core.report``.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import warnings

OLD, NEW = __name__, "train.core"


def _warn(old: str, new: str) -> None:
    warnings.warn(
        f"{old} is deprecated and will be removed in the next version: use {new}",
        DeprecationWarning,
        stacklevel=3,
    )


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds ``train.bench.X`` as the module ``train.core.X`` (the same object)."""

    def find_spec(self, fullname, path=None, target=None):
        if not fullname.startswith(OLD + "."):
            return None
        new = NEW + fullname[len(OLD) :]
        if importlib.util.find_spec(new) is None:
            return None
        return importlib.machinery.ModuleSpec(fullname, self, is_package=False)

    def __init__(self):
        self._specs = {}

    def create_module(self, spec):
        new = NEW + spec.name[len(OLD) :]
        _warn(spec.name, new)
        module = importlib.import_module(new)
        self._specs[spec.name] = module.__spec__  # the import system overwrites it next
        return module

    def exec_module(self, module):
        """Nothing to run (the module is ``train.core``'s, already imported): its own spec
        back, so that it stays ``train.core.X`` for reloads and reprs."""
        module.__spec__ = self._specs.pop(module.__spec__.name)

    def get_code(self, fullname):
        """The code of ``train.core``'s module, for ``python -m train.bench.X``."""
        new = NEW + fullname[len(OLD) :]
        _warn(f"python -m {fullname}", f"python -m {new}")
        return importlib.util.find_spec(new).loader.get_code(new)


if not any(isinstance(f, _Alias) for f in sys.meta_path):
    sys.meta_path.append(_Alias())

_warn(OLD, NEW)


def __getattr__(name: str):
    """``train.bench.X`` as an attribute: ``train.core.X`` (through the alias, warning once)."""
    if importlib.util.find_spec(f"{NEW}.{name}") is None:
        raise AttributeError(f"module {OLD!r} has no attribute {name!r}")
    return importlib.import_module(f"{OLD}.{name}")
