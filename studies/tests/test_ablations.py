"""The ablation configs of ``studies/ablations/``: each validates against today's
:class:`train.config.TrainConfig` (or is stale: it names an option since removed from the
package, listed in :data:`STALE`, and is refused naming that option), and their chain of
``base:`` files records the recipes' history, one change at a time."""

from pathlib import Path

import pytest

from train.config import ALGOS, load_config, read_config

ABLATIONS = Path(__file__).resolve().parents[1] / "ablations"
NAMES = sorted(p.stem for p in ABLATIONS.glob("ablation_*.yaml"))

#: Ablations that use a training option removed from the package (``average``,
#: ``anneal_std``, ``episode_scale``: no shipped recipe used them; issue 68), themselves or
#: through their base: the name and the option. Run them with the package version of their
#: commit (``studies/README.md``).
STALE: dict[str, str] = {
    "ablation_ppo_60m_small_steps": "anneal_std",
    "ablation_ppo_anneal_std": "anneal_std",
    "ablation_ppo_anneal_std_005_v015": "anneal_std",
    "ablation_ppo_anneal_std_10m": "anneal_std",
    "ablation_ppo_anneal_std_ent_04_v015": "anneal_std",
    "ablation_ppo_anneal_std_v015": "anneal_std",
    "ablation_ppo_average": "average",
    "ablation_ppo_ent_03_average": "average",
    "ablation_ppo_ent_04_gamma_9995_anneal_std": "anneal_std",
    "ablation_ppo_episode_returns": "anneal_std",
    "ablation_ppo_episode_returns_32envs": "anneal_std",
    "ablation_ppo_gamma": "episode_scale",
    "ablation_ppo_long_anneal": "anneal_std",
    "ablation_ppo_long_small_steps": "anneal_std",
    "ablation_ppo_mlp_critic": "episode_scale",
    "ablation_ppo_no_episode_scale": "episode_scale",
    "ablation_ppo_no_sde": "episode_scale",
    "ablation_ppo_no_whiten": "episode_scale",
    "ablation_ppo_recipe": "episode_scale",
    "ablation_sac_average": "average",
}


def ablation(name: str) -> tuple[str, dict]:
    """``read_config`` of ``studies/ablations/<name>.yaml``."""
    return read_config(ABLATIONS / f"{name}.yaml")


def test_there_are_ablations_and_no_recipe_among_them():
    assert len(NAMES) > 100
    recipes = {p.stem for p in (Path(__file__).resolve().parents[2] / "train/recipes").glob("*")}
    assert not recipes & set(NAMES)
    assert not any(n.startswith("ablation_") for n in recipes)


@pytest.mark.parametrize("name", NAMES)
def test_every_ablation_validates_or_is_stale(name):
    path = ABLATIONS / f"{name}.yaml"
    if name in STALE:
        with pytest.raises(ValueError, match=STALE[name]):
            load_config(path)
        return
    cfg = load_config(path)
    assert cfg.algo in ALGOS and cfg.timesteps > 0
    assert ablation(name)[0] == name


def test_the_chain_records_the_recipes_history_one_change_at_a_time():
    """Each base is an older recipe kept whole (``ablation_ppo_v015``: 0.15.0-0.17.1's PPO,
    ``ablation_ppo_independent``: 0.8.0-0.14.0's, ...); a file on it changes what it says."""
    _, ppo = ablation("ablation_ppo_v015")  # acld-gym 0.15.0-0.17.1's recipe, whole
    _, independent = ablation("ablation_ppo_independent")  # acld-gym 0.8.0-0.14.0's, whole
    pk = {
        k: v
        for k, v in ppo["model"]["policy_kwargs"].items()
        if k not in ("antithetic_noise", "critic_features")
    }
    assert independent == {
        **{k: v for k, v in ppo.items() if k != "paired_loads"},
        "model": {**ppo["model"], "ent_coef": 0.03, "policy_kwargs": pk},
    }
    _, paired = ablation("ablation_ppo_antithetic_ent_05")  # chained on it: two changes
    assert paired == {
        **independent,
        "paired_loads": True,
        "model": {
            **independent["model"],
            "ent_coef": 0.05,
            "policy_kwargs": {**pk, "antithetic_noise": True},
        },
    }
    _, negative = ablation("ablation_ppo_negative_critic")  # on it: the critic alone
    assert negative == {
        **independent,
        "model": {
            **independent["model"],
            "policy_kwargs": {**pk, "critic_features": "negative_scaled_quadratic"},
        },
    }
    # acld-gym 0.15.0's recipe: the two together
    assert ppo == {
        **paired,
        "model": {
            **paired["model"],
            "policy_kwargs": {
                **paired["model"]["policy_kwargs"],
                "critic_features": "negative_scaled_quadratic",
            },
        },
    }
    # 0.18.0's: a run retried above 0.520 on validation, not above LQR's cost
    assert ablation("ablation_ppo_retry_above_0520")[1] == {**ppo, "restart_above": 0.52}
    assert ablation("ablation_ppo_lowest_of_5")[1] == {
        **ppo,
        "restarts": 5,
        "restart_above": None,
    }
    _, one_run = ablation("ablation_ppo_one_run")  # acld-gym 0.7.0's recipe: one run
    assert one_run == {**independent, "restarts": 1, "restart_above": None, "select": None}
    _, old = ablation("ablation_ppo_ent_01")  # 0.6.0's: chained on 0.7.0's, one change
    assert old == {**one_run, "model": {**one_run["model"], "ent_coef": 0.01}}
    _, lam = ablation("ablation_ppo_lambda_095")  # chained: on 0.6.0's recipe
    assert lam == {**old, "model": {**old["model"], "gae_lambda": 0.95}}
    _, sac = read_config("sac")
    _, three_runs = ablation("ablation_sac_three_runs")  # acld-gym 0.9.0's SAC recipe
    assert three_runs == {**sac, "restarts": 3, "restart_above": None}
    _, two_runs = ablation("ablation_sac_two_runs")  # 0.8.0's: chained on 0.9.0's
    assert two_runs == {**three_runs, "restarts": 2}
    _, lqr_scale = ablation("ablation_sac_lqr_scale")  # measured against 0.8.0's
    assert lqr_scale == {
        **two_runs,
        "env_kwargs": {**two_runs["env_kwargs"], "reward_scale": "lqr"},
    }
