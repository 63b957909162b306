"""Deprecation shims: the flat module paths of acld-gym 0.1 for one version."""

from __future__ import annotations

import warnings


def moved(old: str, new: str) -> None:
    """Warn (``DeprecationWarning``) that module ``old`` moved to ``new``."""
    warnings.warn(f"{old} moved to {new} in acld-gym 0.2; the old path goes in 0.3",
                  DeprecationWarning, stacklevel=3)
