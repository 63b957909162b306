"""Files the training core reads: a key given twice in a config is refused (plain YAML keeps
the last one silently); the recipes load. A damaged references cache is
tests/baselines/evaluation/test_references.py's."""

import pytest

from acld_gym.util.validate import DataFileError
from train.config import load_config


def test_a_key_given_twice_is_refused_naming_file_line_and_key(tmp_path):
    path = tmp_path / "twice.yaml"
    path.write_text("base: ppo\ntimesteps: 1000\ntimesteps: 2000\n")
    with pytest.raises(DataFileError, match=r"twice\.yaml: .*line 3.*'timesteps' given twice"):
        load_config(path)
    nested = tmp_path / "nested.yaml"
    nested.write_text("base: ppo\nmodel:\n  gamma: 0.99\n  gamma: 0.9\n")
    with pytest.raises(DataFileError, match="'gamma' given twice"):
        load_config(nested)


def test_yaml_merge_keys_and_the_recipes_still_load(tmp_path):
    path = tmp_path / "merge.yaml"
    path.write_text("base: ppo\nx: &a {reward_scale: passive}\nenv_kwargs:\n  <<: *a\n")
    with pytest.raises(DataFileError, match="unknown key"):  # x is no setting: parsed first
        load_config(path)
    for name in ("ppo", "sac", "vrs"):
        assert load_config(name).timesteps > 0
