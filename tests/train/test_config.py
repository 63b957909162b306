"""train.config: the one training configuration (the recipes under train/recipes/) and
its validation. The research record's variants (``studies/ablations/``) are checked by
``studies/tests/test_ablations.py``, outside the default run."""

import pytest

from train.config import (
    ALGOS,
    CONFIG_DIR,
    TrainConfig,
    config_path,
    load_config,
    parse_load_case,
    read_config,
)

RECIPES = sorted(p.stem for p in CONFIG_DIR.glob("*.yaml"))


@pytest.mark.parametrize("name", RECIPES)
def test_every_recipe_file_validates(name):
    cfg = load_config(name)
    assert cfg.algo in ALGOS and cfg.timesteps > 0
    assert read_config(name) == (name, read_config(config_path(name))[1])
    if cfg.algo != "vrs":
        assert 0 < cfg.gamma <= 1 and "policy" in cfg.model


def test_recipes_are_from_scratch_unless_named_so():
    for name in RECIPES:
        cfg = load_config(name)
        if "dagger" in name:
            assert cfg.teacher == "mpc" and cfg.training.startswith("DAgger from MPC + RL")
        else:
            assert cfg.teacher is None and cfg.training == "from scratch", name


def test_overrides_revalidate():
    cfg = load_config("ppo")
    many = cfg.whiten_steps + 10
    assert cfg.with_overrides(timesteps=many, n_envs=None).timesteps == many
    assert cfg.with_overrides(timesteps=many).n_envs == cfg.n_envs
    with pytest.raises(ValueError, match="timesteps"):
        cfg.with_overrides(timesteps=-5)
    with pytest.raises(ValueError, match="must be more than whiten_steps"):
        cfg.with_overrides(timesteps=cfg.whiten_steps)  # the whitening is in the budget


BASE = dict(algo="ppo", timesteps=10, n_envs=2, model={"policy": "MlpPolicy"})


@pytest.mark.parametrize(
    "change, word",
    [
        ({"algo": "dqn"}, "algo"),
        ({"n_envs": 0}, "n_envs"),
        ({"loads": {4: 1}}, "1, 2, 3"),
        ({"loads": {1: 0}}, "loads"),
        ({"loads": {1: True}}, "loads"),
        ({"env_kwargs": {"param_noise": -0.1}}, "param_noise"),
        ({"env_kwargs": {"load_case": 1}}, "loads"),
        ({"env_kwargs": {"reward_scael": "passive"}}, "reward_scael"),
        ({"residual": "mpc"}, "residual"),
        ({"shaping": 0}, "shaping"),
        ({"action_headroom": 0.5}, "action_headroom"),
        ({"action_headroom": "2"}, "action_headroom"),
        ({"model": {}}, "policy"),
        ({"model": {"policy": "MlpPolicy", "learning_rat": 1}}, "learning_rat"),
        ({"model": {"policy": "MlpPolicy", "n_steps": "64"}}, "n_steps"),
        ({"model": {"policy": "MlpPolicy", "max_grad_norm": "1.0e6"}}, "max_grad_norm"),
        ({"model": {"policy": "MlpPolicy", "gamma": 1.01}}, "model.gamma"),
        ({"model": {"policy": "MlpPolicy", "gamma": 0}}, "model.gamma"),
        ({"model": {"policy": "MlpPolicy", "gae_lambda": 1.5}}, "model.gae_lambda"),
        ({"normalize": {"norm_obbs": True}}, "norm_obbs"),
        ({"features": "fourier"}, "features"),
        ({"paired_loads": 1}, "paired_loads must be"),
        ({"paired_loads": True, "n_envs": 3}, "paired_loads needs an even.*'random': 3"),
        ({"paired_loads": True, "n_envs": 4, "loads": {1: 1, 2: 3}}, "paired_loads needs"),
        ({"whiten_steps": 100, "features": "direction"}, "whiten_steps"),
        ({"distill": {"itertions": 3}}, "itertions"),
        ({"distill": {"teacher": "mpc"}, "residual": "lqr"}, "residual"),
        ({"select": 5}, "select"),
        ({"select": {"episodes": 4}}, "select.*missing.*every"),
        ({"select": {"episodes": 4, "every": 10, "strat": 1}}, "select.*strat"),
        ({"select": {"episodes": 0, "every": 10}}, "select.episodes"),
        ({"select": {"episodes": 4, "every": 10, "start": -1}}, "select.start"),
        ({"select": {"episodes": 4, "every": 10}, "normalize": {"norm_obs": True}}, "norm_obs"),
    ],
)
def test_bad_values_name_the_field(change, word):
    with pytest.raises(ValueError, match=word):
        TrainConfig(**{**BASE, **change})


@pytest.mark.parametrize(
    "key, value",
    [("average", {"start": 10}), ("anneal_std", {"start": 0, "end": 0.5}), ("episode_scale", True)],
)
def test_removed_research_options_are_unknown_keys(key, value):
    """Options no shipped recipe used went with the research record (acld-gym 0.20.0,
    ``studies/``): a config naming one is refused naming it, as any unknown key."""
    with pytest.raises(ValueError, match=rf"unknown key\(s\) \['{key}'\]"):
        TrainConfig.from_dict({**BASE, key: value})


def test_vrs_takes_no_sb3_options():
    with pytest.raises(ValueError, match="SB3"):
        TrainConfig(algo="vrs", timesteps=10, shaping=0.1)
    # its candidates' episodes take the env's options, but not log c in its observation
    TrainConfig(algo="vrs", timesteps=10, env_kwargs={"reward_scale": "passive"})
    with pytest.raises(ValueError, match="env_kwargs: observe_reward_scale is for the SB3"):
        TrainConfig(
            algo="vrs",
            timesteps=10,
            env_kwargs={"reward_scale": "passive", "observe_reward_scale": True},
        )
    with pytest.raises(ValueError, match="action_headroom is for the SB3"):
        TrainConfig(algo="vrs", timesteps=10, action_headroom=2.0)
    with pytest.raises(ValueError, match="distill and select are for the SB3"):
        TrainConfig(algo="vrs", timesteps=10, select={"episodes": 2, "every": 10})
    with pytest.raises(ValueError, match="paired_loads.*SB3"):
        TrainConfig(algo="vrs", timesteps=10, paired_loads=True)


def test_envs_per_load_splits_the_sub_envs_by_weight():
    split = TrainConfig(**{**BASE, "n_envs": 8, "loads": {1: 1, "random": 3}}).envs_per_load
    assert split == {1: 2, "random": 6}
    assert TrainConfig(**{**BASE, "n_envs": 2, "loads": {1: 1, 2: 1, 3: 1}}).envs_per_load == {
        1: 1,
        2: 1,
        3: 1,
    }  # at least one sub-env per load case


def test_bad_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_config(tmp_path / "nope.yaml")
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_config("no_such_recipe")
    bad = tmp_path / "bad.yaml"
    bad.write_text("algo: ppo\ntimesteps: 10\nlearning_rat: 1\nmodel: {policy: MlpPolicy}\n")
    with pytest.raises(ValueError, match="bad.yaml.*learning_rat"):
        load_config(bad)
    bad.write_text("algo: ppo\nmodel: {policy: MlpPolicy}\n")
    with pytest.raises(ValueError, match="missing.*timesteps"):
        load_config(bad)
    bad.write_text("algo: ppo\n  timesteps: [\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        load_config(bad)


@pytest.mark.parametrize("value, expected", [(1, 1), ("2", 2), (3, 3), ("random", "random")])
def test_parse_load_case_accepts_the_cases(value, expected):
    assert parse_load_case(value) == expected


@pytest.mark.parametrize("value", [0, 4, "4", True, "Random", None, 1.5, 1.0])
def test_parse_load_case_names_the_choices(value):
    with pytest.raises(ValueError, match="1, 2, 3 or 'random'"):
        parse_load_case(value)


def test_base_applies_the_recipe_under_a_files_own_settings(tmp_path):
    """``base:`` names a recipe; the file's settings go on top, nested mappings key by key."""
    _, ppo = read_config("ppo")
    (tmp_path / "a.yaml").write_text(
        "base: ppo\ntimesteps: 300000\nmodel: {policy_kwargs: {log_std_init: -2.0}}\n"
    )
    _, data = read_config(tmp_path / "a.yaml")
    assert data["timesteps"] == 300000 and "base" not in data
    assert data["model"]["policy_kwargs"] == {**ppo["model"]["policy_kwargs"], "log_std_init": -2.0}
    assert data["model"]["n_steps"] == ppo["model"]["n_steps"]
    (tmp_path / "b.yaml").write_text(f"base: {tmp_path / 'a.yaml'}\nn_envs: 8\n")
    _, chained = read_config(tmp_path / "b.yaml")
    assert chained == {**data, "n_envs": 8}


def test_a_base_name_is_first_a_file_beside_the_config(tmp_path):
    """``base: NAME`` is ``NAME.yaml`` in the config's own folder if there is one (a chain
    kept together, as ``studies/ablations/``), else the recipe ``NAME``; and a sibling
    named like a recipe takes precedence over the recipe for that folder only."""
    (tmp_path / "first.yaml").write_text("base: ppo\ntimesteps: 300000\n")
    (tmp_path / "second.yaml").write_text("base: first\nn_envs: 8\n")
    _, ppo = read_config("ppo")
    assert read_config(tmp_path / "second.yaml") == (
        "second",
        {**ppo, "timesteps": 300000, "n_envs": 8},
    )
    (tmp_path / "ppo.yaml").write_text("base: sac\n")  # not the recipe ppo, beside first.yaml
    _, sac = read_config("sac")
    assert read_config(tmp_path / "first.yaml")[1] == {**sac, "timesteps": 300000}
    assert read_config("ppo")[1] == ppo  # the recipe itself is untouched
    (tmp_path / "loop.yaml").write_text("base: loop\n")
    with pytest.raises(ValueError, match="leads back to itself"):
        read_config(tmp_path / "loop.yaml")


@pytest.mark.parametrize(
    "text, match",
    [
        ("base: 3\n", r"base: expected a config name or path, got 3"),
        ("base: no_such_recipe\n", r"no_such_recipe.*does not exist"),
        ("base: ppo\ntimesteps: -5\n", r"c.yaml: timesteps must be an integer"),
    ],
)
def test_base_errors_name_the_file_and_the_problem(tmp_path, text, match):
    (tmp_path / "c.yaml").write_text(text)
    with pytest.raises((ValueError, FileNotFoundError), match=match):
        read_config(tmp_path / "c.yaml")


def test_base_refuses_a_cycle(tmp_path):
    (tmp_path / "x.yaml").write_text(f"base: {tmp_path / 'y.yaml'}\n")
    (tmp_path / "y.yaml").write_text(f"base: {tmp_path / 'x.yaml'}\n")
    with pytest.raises(ValueError, match="leads back to itself"):
        read_config(tmp_path / "x.yaml")
