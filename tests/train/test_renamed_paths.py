"""The old import paths of the renamed modules (acld-gym 0.21.0) keep working for one more
version: each warns once with a ``DeprecationWarning`` naming its new path, and gives the
very objects of the new one. ``train.bench`` -> :mod:`train.core`, ``acld_gym.benchmark`` ->
:mod:`acld_gym.test_sets`; the recipes are ``train/recipes/``."""

from __future__ import annotations

import importlib
import subprocess
import sys
import warnings

import pytest

import acld_gym.test_sets
from train.config import CONFIG_DIR, load_config
from train.core import evaluate as core_evaluate
from train.core import report as core_report
from train.core import trials as core_trials


def _fresh(*names):
    """Forget ``names`` (and their submodules) so that the next import runs them again."""
    for n in list(sys.modules):
        if any(n == m or n.startswith(m + ".") for m in names):
            del sys.modules[n]


def test_acld_gym_benchmark_warns_naming_test_sets_and_gives_the_same_objects():
    _fresh("acld_gym.benchmark")
    with pytest.warns(DeprecationWarning, match=r"acld_gym\.benchmark .* use acld_gym\.test_sets"):
        old = importlib.import_module("acld_gym.benchmark")
    assert set(old.__all__) == set(acld_gym.test_sets.__all__)
    for name in acld_gym.test_sets.__all__:
        assert getattr(old, name) is getattr(acld_gym.test_sets, name), name


def test_train_bench_and_its_submodules_are_train_core_with_one_warning_each():
    _fresh("train.bench")
    with pytest.warns(DeprecationWarning) as got:
        import train.bench.evaluate as old_evaluate
        from train.bench.trials import run_trial

        from train.bench import report
    said = sorted(str(w.message).split(" is deprecated")[0] for w in got)
    assert said == [f"train.bench{m}" for m in ("", ".evaluate", ".report", ".trials")]
    assert all("use train.core" in str(w.message) for w in got)
    assert old_evaluate is core_evaluate and report is core_report
    assert run_trial is core_trials.run_trial
    # the module keeps its own identity (name, spec) and a second access does not warn
    assert core_evaluate.__spec__.name == "train.core.evaluate"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = importlib.import_module("train.bench.evaluate")
        assert again is core_evaluate and sys.modules["train.bench"].evaluate is core_evaluate


def test_a_name_train_core_does_not_have_is_an_attribute_or_import_error():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import train.bench
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        train.bench.nothing  # noqa: B018
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("train.bench.nothing")


def test_python_m_train_bench_report_still_runs_the_report():
    out = subprocess.run(
        [sys.executable, "-W", "default::DeprecationWarning", "-m", "train.bench.report", "--help"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "usage: python -m train.core.report" in out.stdout
    assert "use python -m train.core.report" in out.stderr


def test_a_recipe_name_resolves_to_train_recipes():
    assert CONFIG_DIR.name == "recipes" and CONFIG_DIR.parent.name == "train"
    for name in ("ppo", "sac", "vrs", "ars", "tqc"):
        assert (CONFIG_DIR / f"{name}.yaml").is_file()
        assert load_config(name).algo == name
