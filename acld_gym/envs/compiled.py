"""Which step runs: the compiled one (``acld_gym.envs._stepcore.BatchCore``, built from
``_stepcore.c`` at install) where it was built, else numpy's reference step, which gives
the same numbers 2-5x slower (:mod:`acld_gym.envs.batch` uses both).

The environment variable ``ACLD_GYM_PURE_PYTHON=1``, read at import, asks for the numpy
step (debugging). Without it, an install whose extension was not built (no C compiler)
says so once, at import (:data:`NOT_COMPILED`), instead of running slower in silence.
"""

from __future__ import annotations

import os
import warnings

__all__ = ["BatchCore", "COMPILED_STEP", "NOT_COMPILED"]

#: What a user is told once when the compiled step is missing (not on request).
NOT_COMPILED = (
    "acld_gym: the compiled step (acld_gym.envs._stepcore) is not built, so the envs run "
    "numpy's reference step, the same numbers 2-5x slower; install with a C compiler "
    "present (pip install -e . or make install) to build it"
)

if os.environ.get("ACLD_GYM_PURE_PYTHON") == "1":  # debugging: numpy steps only
    BatchCore = None
else:
    try:
        from ._stepcore import BatchCore
    except ImportError:  # built without a C compiler: the numpy reference step serves
        BatchCore = None
        warnings.warn(NOT_COMPILED, UserWarning, stacklevel=2)

#: Whether the step runs compiled (``acld_gym.envs._stepcore``).
COMPILED_STEP = BatchCore is not None
