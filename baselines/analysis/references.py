"""The import path of :mod:`baselines.evaluation.references` before it moved
(acld-gym 0.21.0): its public names, re-exported (the same objects). New code imports
:mod:`baselines.evaluation.references`."""

from baselines.evaluation.references import *  # noqa: F403 (the old names: the same objects)
from baselines.evaluation.references import __all__  # noqa: F401 (exactly the new home's public names)
