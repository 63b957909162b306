"""Deprecated: the test sets are :mod:`acld_gym.test_sets` (renamed in acld-gym 0.21.0).

Every name of ``acld_gym.benchmark`` is the same object in :mod:`acld_gym.test_sets`, for
one more version; importing this module warns once (a ``DeprecationWarning`` naming the new
path).
"""

from __future__ import annotations

import warnings

from acld_gym import test_sets as _new
from acld_gym.test_sets import *  # noqa: F403 (the old names, the same objects)

__all__ = list(_new.__all__)

warnings.warn(
    "acld_gym.benchmark is deprecated and will be removed in the next version: "
    "use acld_gym.test_sets",
    DeprecationWarning,
    stacklevel=2,
)
