"""The modules that moved into baselines.evaluation keep their old import paths: every public
name of the new home is importable from the old module, as the same object."""

import importlib

import pytest


@pytest.mark.parametrize(
    "old, new",
    [
        ("baselines.rollout", "baselines.evaluation.rollout"),
        ("baselines.analysis.references", "baselines.evaluation.references"),
        ("baselines.analysis.score", "baselines.evaluation.score"),
    ],
)
def test_the_old_path_re_exports_every_public_name(old, new):
    old_module, home = importlib.import_module(old), importlib.import_module(new)
    assert sorted(old_module.__all__) == sorted(home.__all__)
    for name in home.__all__:
        assert getattr(old_module, name) is getattr(home, name), (old, name)
    assert new in old_module.__doc__  # it names the new path
