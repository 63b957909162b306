"""Every repository path the README and the documentation pages name in inline code exists
(a glob matches it): a file moved or deleted leaves no stale pointer behind. Placeholders
(``<hash>``, ``{a,b}``, an upper-case segment such as ``ALGO``) stand for any name."""

import glob
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: The changelog is left out: it is history, naming each path as it was in its version.
PAGES = [
    ROOT / "README.md",
    *sorted(p for p in (ROOT / "docs").rglob("*.md") if p.name != "changelog.md"),
]
#: Top-level directories of the repository whose paths the pages point at.
_PATH = re.compile(
    r"(?<![\w./-])((?:acld_gym|baselines|train|benchmarks|studies|tests|docs|\.ci)"
    r"/[\w./*<>{},-]*[\w*>}])"
)
_PLACEHOLDER = re.compile(r"<[^>]*>|\{[^}]*\}|(?<=/)[A-Z][A-Z_]*(?=[./]|$)")


def named_paths(text: str) -> set[str]:
    """Repository paths in inline code spans (fenced blocks left out), placeholders as
    ``*``."""
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    out = set()
    for span in re.findall(r"`([^`\n]+)`", text):
        out.update(_PLACEHOLDER.sub("*", m) for m in _PATH.findall(span))
    return out


def test_named_paths_parser():
    text = (
        "see `train/recipes/ALGO.yaml` and `acld_gym/physics/data/plant-<hash>.npz`,\n"
        "`python -m train.benchmark --out runs/x` and `tests/{a,b}.py`\n"
        "```bash\ncat train/nothing.yaml\n```\n"
    )
    assert named_paths(text) == {
        "train/recipes/*.yaml",
        "acld_gym/physics/data/plant-*.npz",
        "tests/*.py",
    }


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_named_path_exists(page):
    missing = sorted(p for p in named_paths(page.read_text()) if not glob.glob(str(ROOT / p)))
    assert not missing, f"{page.name} names paths that do not exist: {missing}"
