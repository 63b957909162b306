"""The long train modules split by job (issue 68) keep their public names: each name the old
module exported (its ``__all__`` before the split, pinned here) still imports from it, and is
the very object of the new module that now defines it, so an ``isinstance``, a pickle by
reference or a recipe's ``policy: train.core.sb3_policies.<Class>`` sees one class. The new
modules are small and import each other only downwards (tests/test_architecture.py)."""

from __future__ import annotations

import importlib

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from train.config_yaml import MAX_VALUES, UniqueKeyLoader, check_size

#: module -> its ``__all__`` before the split (acld-gym 0.20).
OLD_NAMES = {
    "train.config": [
        "ALGOS", "SB3_ALGOS", "CONFIG_DIR", "TrainConfig", "SelectConfig", "algo_class",
        "config_path", "read_config", "load_config", "parse_load_case",
    ],
    "train.config_checks": ["check_model", "check_buildable", "check_size", "MAX_VALUES",
                            "MAX_BYTES"],
    "train.agent": [
        "TrainedAgent", "ActorProgram", "AgentFileError", "export_sb3", "actor_extractor",
        "actor_parts", "linear_program", "observation_width", "POLICY_FILE", "META_FILE",
        "MODEL_FILE", "STATS_FILE", "CURVE_FILE", "versions",
    ],
    "train.sb3_export": ["actor_extractor", "actor_parts", "export_sb3"],
    "train.compare": [
        "AGENTS_DIR", "HELDOUT_SEEDS", "agent_names", "load_agents", "training_labels",
        "reference_policies", "compare", "relative", "markdown_table", "markdown_scores",
        "learning_curves_figure", "plot_learning_curves", "main",
    ],
    "train.figures": ["HERO_CASES", "hero_policies", "hero_data", "hero_figure", "beam_frames",
                      "save_animation", "sparse_ratio_labels", "main"],
    "train.core.report": [
        "GOALS", "goals_of", "summarize", "markdown", "headline", "stretch_lines",
        "seeds_beating_references", "render_blocks", "write_blocks", "ratio_log_axis",
        "curves_figure", "plot_curves",
    ],
    "train.core.sb3_policies": [
        "QuadraticFeatures", "CRITIC_FEATURES", "SplitCriticPolicy", "AsymmetricCriticPolicy",
        "AsymmetricSACPolicy", "ScaledQuadraticCritic", "DropLast", "ScaledQuadraticFeatures",
        "NegativeScaledQuadraticFeature", "SB3Policy",
    ],
    "train.core.search": ["LinearDirectionActor", "whitening", "RandomSearch",
                          "train_random_search"],
}  # fmt: skip

#: A name moved out of an old module -> the module that defines it now.
MOVED = {
    ("train.config", "TrainConfig"): "train.config_schema",
    ("train.config", "SelectConfig"): "train.config_sections",
    ("train.config", "algo_class"): "train.config_algos",
    ("train.config_checks", "check_model"): "train.config_model",
    ("train.config_checks", "check_size"): "train.config_yaml",
    ("train.agent", "ActorProgram"): "train.agent_program",
    ("train.agent", "linear_program"): "train.agent_program",
    ("train.compare", "load_agents"): "train.agent_dirs",
    ("train.compare", "learning_curves_figure"): "train.curves_figure",
    ("train.figures", "sparse_ratio_labels"): "train.curves_figure",
    ("train.core.report", "summarize"): "train.core.report_stats",
    ("train.core.report", "markdown"): "train.core.report_tables",
    ("train.core.report", "curves_figure"): "train.core.report_plots",
    ("train.core.report", "write_blocks"): "train.core.report_pages",
    ("train.core.sb3_policies", "QuadraticFeatures"): "train.core.critic_features",
    ("train.core.sb3_policies", "AsymmetricCriticPolicy"): "train.core.ppo_policies",
    ("train.core.sb3_policies", "AsymmetricSACPolicy"): "train.core.sac_policies",
    ("train.core.sb3_policies", "SB3Policy"): "train.core.sb3_inference",
    ("train.core.search", "RandomSearch"): "train.core.search_settings",
}


@pytest.mark.parametrize("module", sorted(OLD_NAMES))
def test_every_old_name_still_imports_from_its_module(module):
    mod = importlib.import_module(module)
    missing = [n for n in OLD_NAMES[module] if not hasattr(mod, n)]
    assert not missing, f"{module} lost {missing}"
    assert set(OLD_NAMES[module]) <= set(mod.__all__)


@pytest.mark.parametrize(("old", "name"), sorted(MOVED))
def test_a_moved_name_is_the_new_modules_object(old, name):
    new = importlib.import_module(MOVED[(old, name)])
    assert getattr(importlib.import_module(old), name) is getattr(new, name)
    assert name in new.__all__


def test_the_recipes_name_the_policies_where_they_resolve():
    from train.config import load_config
    from train.core import sb3_policies

    for recipe in ("ppo", "sac"):
        name = load_config(recipe).model["policy"]
        cls = getattr(sb3_policies, name)
        assert cls.__module__ in ("train.core.ppo_policies", "train.core.sac_policies")


# --- the config's YAML reader, on its own -----------------------------------------------
def test_a_key_given_twice_is_refused_and_a_merge_key_may_be_replaced():
    with pytest.raises(yaml.constructor.ConstructorError, match="key 'a' given twice"):
        yaml.load("a: 1\na: 2\n", Loader=UniqueKeyLoader)  # noqa: S506 (a safe loader)
    text = "base: &b {a: 1}\nx:\n  <<: *b\n  a: 2\n"
    assert yaml.load(text, Loader=UniqueKeyLoader)["x"] == {"a": 2}  # noqa: S506


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 3 * MAX_VALUES))
def test_check_size_counts_every_value(n):
    data = {"k": list(range(n))}  # the mapping, its key, its list and n items
    if n + 3 > MAX_VALUES:
        with pytest.raises(ValueError, match=f"f.yaml: more than {MAX_VALUES} values"):
            check_size(data, "f.yaml")
    else:
        check_size(data, "f.yaml")
