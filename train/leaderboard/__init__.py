"""The leaderboard of every level, generated from committed data.

* :mod:`train.leaderboard.schema`: the data, one JSON file per level
  (``results/<env id>.json``), and its checks;
* :mod:`train.leaderboard.measure`: one policy's numbers (score v2, ISE relative to the
  thesis LQR per case, effort after settling) by the package's own evaluators;
* :mod:`train.leaderboard.collect`: a level's references and a benchmark folder's agents,
  merged into its file with provenance;
* :mod:`train.leaderboard.render`: the page ``docs/leaderboard.md``, from the data alone;
* :mod:`train.leaderboard.readme`: the README's block, from the same data;
* :mod:`train.leaderboard.cli`: ``python -m train.leaderboard collect|render``
  (``acld-gym leaderboard``).
"""

from .readme import END, START
from .render import COMMAND
from .schema import FORMAT, check_level, read_level

__all__ = ["FORMAT", "check_level", "read_level", "START", "END", "COMMAND"]
