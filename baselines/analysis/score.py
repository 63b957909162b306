"""The import path of :mod:`baselines.evaluation.score` before it moved
(acld-gym 0.21.0): its public names, re-exported (the same objects). New code imports
:mod:`baselines.evaluation.score`."""

from baselines.evaluation.score import *  # noqa: F403 (the old names: the same objects)
from baselines.evaluation.score import __all__  # noqa: F401 (exactly the new home's public names)
