"""train.config: the YAML hyperparameters and their validation."""

import pytest

from train.config import ALGOS, TrainConfig, config_path, load_config, parse_load_case


@pytest.mark.parametrize("algo", ALGOS)
def test_shipped_yaml_loads(algo):
    cfg = load_config(algo)
    assert cfg.algo == algo and cfg.load_case == "random"
    assert cfg.model["policy"] == "MlpPolicy"
    assert 0 < cfg.gamma < 1
    assert config_path(algo).name == f"{algo}.yaml"


def test_overrides_revalidate():
    cfg = load_config("ppo")
    assert cfg.with_overrides(n_timesteps=10, load_case=None).n_timesteps == 10
    assert cfg.with_overrides(n_timesteps=10).load_case == cfg.load_case
    with pytest.raises(ValueError, match="n_timesteps"):
        cfg.with_overrides(n_timesteps=-5)


@pytest.mark.parametrize("change, word", [
    ({"algo": "dqn"}, "algo"), ({"n_envs": 0}, "n_envs"), ({"load_case": 4}, "load_case"),
    ({"load_case": True}, "load_case"), ({"param_noise": -0.1}, "param_noise"),
    ({"residual": "mpc"}, "residual"), ({"shaping": 0}, "shaping"),
    ({"model": {}}, "policy"),
])
def test_bad_values_name_the_field(change, word):
    base = dict(algo="ppo", n_timesteps=10, n_envs=2, model={"policy": "MlpPolicy"})
    with pytest.raises(ValueError, match=word):
        TrainConfig(**{**base, **change})


def test_bad_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_config("ppo", tmp_path / "nope.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("n_timesteps: 10\nn_envs: 2\nlearning_rat: 1\nmodel: {policy: MlpPolicy}\n")
    with pytest.raises(ValueError, match="learning_rat"):
        load_config("ppo", bad)
    with pytest.raises(ValueError, match="algo"):
        config_path("a2c")


@pytest.mark.parametrize("value, expected", [(1, 1), ("2", 2), (3, 3), ("random", "random")])
def test_parse_load_case_accepts_the_cases(value, expected):
    assert parse_load_case(value) == expected


@pytest.mark.parametrize("value", [0, 4, "4", True, "Random", None, 1.5, 1.0])
def test_parse_load_case_names_the_choices(value):
    with pytest.raises(ValueError, match="1, 2, 3 or 'random'"):
        parse_load_case(value)
