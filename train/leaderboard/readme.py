"""The README's block of the leaderboard: one compact table, generated from the same data as
the page (:mod:`train.leaderboard.render`), between :data:`START` and :data:`END`.

Rows are the levels (every id of :data:`acld_gym.envs.presets.PRESETS`), columns the best
engineer's design, the plant oracle and the IQM over the seeds of PPO, SAC and the random
search (:data:`README_ALGOS`), each score v2 on the level's test set; "not run" where a
level has no data yet, "(reduced)" after a score on fewer episodes than the published set.
"""

from __future__ import annotations

from pathlib import Path

from acld_gym.envs.presets import PRESETS
from acld_gym.test_sets import TEST_SETS
from acld_gym.util.validate import file_error

from .render import COMMAND, marks

__all__ = ["START", "END", "README_ALGOS", "readme_block", "replace_block"]

START = "<!-- leaderboard:start -->"
END = "<!-- leaderboard:end -->"
#: The README's algorithm columns: (name in the results, heading).
README_ALGOS = (("ppo", "PPO"), ("sac", "SAC"), ("vrs", "random search"))


def readme_block(levels: dict[str, dict]) -> str:
    """The README's block, markers included: per level the best engineer's, the plant
    oracle's and each algorithm's IQM score ("not run" where there is no data)."""
    heads = ["level", "best engineer", "plant oracle", *(h for _, h in README_ALGOS)]
    rows = ["| " + " | ".join(heads) + " |", "|---" * len(heads) + "|"]
    for env_id in PRESETS:
        level = levels.get(env_id) or {"references": None, "agents": {}}
        m = marks(level)
        cells = [f"`{env_id}`"]
        full = len(TEST_SETS[env_id].seeds)
        for key in ("engineer", "oracle"):
            v = m[key]
            cells.append(
                "not run"
                if v is None
                else f"{v[1]['score']['iqm']:.3f} (`{v[0]}`){_short(v[1]['score'], full)}"
            )
        for name, _ in README_ALGOS:
            a = level["agents"].get(name)
            cells.append(
                "not run"
                if a is None
                else f"{a['iqm']['score']['iqm']:.3f} ({len(a['seeds'])} seeds)"
                f"{_short(a['seeds'][0]['score'], full)}"
            )
        rows.append("| " + " | ".join(cells) + " |")
    lead = (
        "- **The leaderboard of every level** ([docs/leaderboard.md](docs/leaderboard.md), "
        f"generated from `results/<env id>.json` by `{COMMAND}`): score v2, the IQM on each "
        "level's test set (passive 0, clairvoyant bound 1; an algorithm's is the IQM over "
        "its seeds); every policy with its interval, ISE relative to the thesis LQR, effort "
        "and training time is on the page."
    )
    return "\n".join([START, "", lead, "", *rows, "", END])


def _short(score: dict, full: int) -> str:
    """ " (reduced)" for a score on fewer episodes than the published test set's."""
    return " (reduced)" if score["n_episodes"] < full else ""


def replace_block(
    text: str, block: str, path: str | Path, start: str = START, end: str = END
) -> str:
    """``text`` with what lies between ``start`` and ``end`` (markers included; default
    :data:`START` and :data:`END`) replaced by ``block``; ``DataFileError`` naming ``path``
    unless each marker is there once, in order."""
    if text.count(start) != 1 or text.count(end) != 1 or text.index(start) > text.index(end):
        raise file_error(path, None, f"expected one {start} and one {end} after it")
    head, rest = text.split(start)
    return head + block + rest.split(end, 1)[1]
