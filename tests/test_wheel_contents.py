"""The wheel carries the product, not the research record: the training recipes, the
shipped agents, the plant data and the step's C source, and no ablation config, research
probe, speed script or test (``studies/``, ``benchmarks/``, ``tests/`` stay in the
repository). The wheel is built as ``make wheel-check`` builds it (``pip wheel --no-deps
--no-build-isolation``), from a copy of the checkout without its build products (about 5 s:
the C step is compiled)."""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: What the copy leaves out: version control, the venv, build and run products.
_SKIP = shutil.ignore_patterns(
    ".git", ".venv", "runs", "results", "site", "build", "dist", "__pycache__", "*.so",
    "*.egg-info", ".pytest_cache", ".ruff_cache", ".hypothesis",
)  # fmt: skip
#: The recipes ``python -m train <recipe>`` and the docs name.
RECIPES = {"ppo", "sac", "vrs", "ars", "tqc", "ppo_dagger", "sac_dagger"}


@pytest.fixture(scope="module")
def members(tmp_path_factory) -> list[str]:
    """The file names in the wheel built from a fresh copy of the checkout."""
    tmp = tmp_path_factory.mktemp("wheel")
    src, out = tmp / "src", tmp / "dist"
    shutil.copytree(ROOT, src, ignore=_SKIP)
    cmd = [sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "--no-build-isolation"]
    cmd += ["--disable-pip-version-check", "-w", str(out), str(src)]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    (wheel,) = out.glob("acld_gym-*.whl")
    with zipfile.ZipFile(wheel) as zf:
        names = zf.namelist()
    shutil.rmtree(tmp)
    return names


def test_no_ablation_probe_speed_script_or_test_in_the_wheel(members):
    probes = {p.name for p in (ROOT / "studies" / "probes").glob("*.py")}
    assert len(probes) >= 10  # the check below has names to look for
    bad = [
        m
        for m in members
        if "ablation" in m.lower()
        or m.split("/")[0] in ("studies", "benchmarks", "tests", "docs", "runs")
        or ("/" in m and m.rsplit("/", 1)[1] in probes)
    ]
    assert not bad, f"research record in the wheel: {bad[:10]}"
    tops = {m.split("/")[0] for m in members}
    assert {t for t in tops if not t.endswith(".dist-info")} == {"acld_gym", "baselines", "train"}


def test_the_recipes_are_in_the_wheel_and_only_they(members):
    shipped = {m for m in members if m.startswith("train/recipes/") and m.endswith(".yaml")}
    in_tree = {f"train/recipes/{p.name}" for p in (ROOT / "train/recipes").glob("*.yaml")}
    assert shipped == in_tree
    assert {Path(m).stem for m in shipped} >= RECIPES


def test_the_shipped_agents_data_and_step_source_are_in_the_wheel(members):
    agents = {
        p.relative_to(ROOT).as_posix()
        for p in (ROOT / "train/agents").rglob("*")
        if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc"
    }
    assert {"train/agents/ppo/policy.npz", "train/agents/vrs/metadata.json"} <= agents
    assert agents <= set(members)
    assert "acld_gym/envs/_stepcore.c" in members
    assert any(m.startswith("acld_gym/physics/data/") and m.endswith(".npz") for m in members)
    assert "train/config.py" in members and "baselines/policies.py" in members
