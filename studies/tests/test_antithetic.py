"""``studies/probes/antithetic.py``: the probe is the recipe with the package's paired loads
and antithetic gain noise (each switchable), one run per seed, and its training env and
policy pair the sub-envs as it says."""

import dataclasses

import numpy as np
import torch

from studies.tests.probe_scripts import load_probe, tiny_model

an = load_probe("antithetic")


def test_the_probe_is_the_recipe_with_pairs_and_antithetic_noise():
    from train.config import load_config

    load_study_config = load_probe("probe").load_study_config
    base, cfg = load_study_config("ablation_ppo_independent"), an.config()  # 0.8.0-0.14.0's recipe
    assert cfg.paired_loads and cfg.model["policy_kwargs"]["antithetic_noise"] is True
    assert cfg.restarts == 1 and not base.paired_loads
    assert cfg.env_kwargs == base.env_kwargs and cfg.model["ent_coef"] == base.model["ent_coef"]
    recipe, adopted = load_config("ppo"), an.config(ent_coef=0.05)  # 0.15.0's, with its critic
    fields = {f.name for f in dataclasses.fields(recipe)} - {"model", "restarts", "restart_above"}
    assert {f: getattr(adopted, f) for f in fields} == {f: getattr(recipe, f) for f in fields}
    critic = {"critic_features": "negative_scaled_quadratic"}  # the recipe's other change
    pk = {**adopted.model["policy_kwargs"], **critic}
    assert {
        **adopted.model,
        "policy": "AsymmetricCriticPolicy",
        "policy_kwargs": pk,
    } == recipe.model
    assert (adopted.restarts, adopted.restart_above) == (1, None)
    bench = load_study_config("ablation_ppo_antithetic")  # the same with the recipe's retry
    assert bench.paired_loads and bench.model["policy_kwargs"] == cfg.model["policy_kwargs"]
    off = an.config(pairs=False, antithetic=False, reward_scale="lqr", ent_coef=0.05)
    assert not off.paired_loads and off.model["policy_kwargs"]["antithetic_noise"] is False
    assert off.env_kwargs["reward_scale"] == "lqr" and off.model["ent_coef"] == 0.05


def test_the_pairs_see_one_load_and_opposite_gain_noise():
    from dataclasses import replace

    from train.vec import make_vec_env

    venv = make_vec_env(replace(an.config(), n_envs=4), 0)
    obs = venv.reset()
    venv.close()
    np.testing.assert_array_equal(obs[0::2], obs[1::2])
    assert not np.array_equal(obs[0], obs[2])
    model, _ = tiny_model(an.config())
    model.policy.reset_noise(4)
    e = model.policy.action_dist.exploration_matrices
    assert torch.equal(e[1::2], -e[0::2])
