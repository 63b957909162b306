"""The checks of a training config's fields together (:func:`check_config`, run by
:class:`train.config.TrainConfig` when it is built): each field's type and range, the
combinations that do not go together (``whiten_steps`` with ``features``, ``paired_loads``
with an odd number of sub-envs per load case, the SB3-only options on ``vrs``, ...), the
training env's options by the env's own config, the sub-mappings by their dataclasses, and
the ``model:`` mapping (:func:`train.config_model.check_model`)."""

from __future__ import annotations

from acld_gym.envs.config import make_config
from acld_gym.physics.loads import parse_load_case
from acld_gym.util.validate import check_int, check_real
from acld_gym.wrappers import check_headroom

from .config_algos import ALGOS
from .config_model import check_model
from .config_sections import SECTIONS, section
from .core.threshold import RestartRule

__all__ = ["RESIDUALS", "check_config"]

#: The values of ``residual``: none, or the discrete LQR's voltage.
RESIDUALS = (None, "lqr")


def check_config(cfg) -> None:
    """``ValueError`` naming the field unless the :class:`train.config.TrainConfig` ``cfg``
    is one a run can take (the checks of its ``__post_init__``, in order)."""
    if cfg.algo not in ALGOS:
        raise ValueError(f"algo must be one of {list(ALGOS)}, got {cfg.algo!r}")
    for name, most in (("timesteps", 10**12), ("n_envs", 2**16), ("eval_points", 10**4)):
        check_int(name, getattr(cfg, name), 1, most)  # most: what memory allows
    check_int("restarts", cfg.restarts, 1, 64)
    if cfg.restart_above is not None:
        RestartRule.parse(cfg.restart_above)
        if cfg.restarts < 2:
            raise ValueError(
                f"restart_above needs restarts >= 2 (runs to choose from), "
                f"got restarts {cfg.restarts}"
            )
    if not isinstance(cfg.loads, dict) or not cfg.loads:
        raise ValueError(f"loads must map cases to positive weights, got {cfg.loads!r}")
    for case, w in cfg.loads.items():
        parse_load_case(case)
        if cfg.algo == "vrs":  # episodes per candidate and iteration
            check_int(f"loads.{case}", w, 1, 10**4)
        else:  # the sub-envs' shares
            check_real(f"loads.{case}", w, 0.0, 1e6, low_open=True)
    if cfg.features not in (None, "direction"):
        raise ValueError(f"features must be 'direction' or null, got {cfg.features!r}")
    sb3 = cfg.algo != "vrs"
    if not isinstance(cfg.model, dict):
        raise ValueError(f"model must be a mapping, got {cfg.model!r}")
    if sb3 and "policy" not in cfg.model:
        raise ValueError(f"{cfg.algo}: model must name the SB3 policy (e.g. policy: MlpPolicy)")
    if (
        isinstance(cfg.whiten_steps, bool)
        or not isinstance(cfg.whiten_steps, int)
        or (cfg.whiten_steps < 0 or (cfg.whiten_steps and cfg.algo in ("vrs", "ars")))
    ):
        raise ValueError(
            f"whiten_steps must be a non-negative integer (SB3 algorithms "
            f"other than ars; vrs: model.whiten), got {cfg.whiten_steps!r}"
        )
    if cfg.whiten_steps and cfg.whiten_steps >= cfg.timesteps:
        raise ValueError(
            f"timesteps ({cfg.timesteps}) must be more than whiten_steps "
            f"({cfg.whiten_steps}): the whitening's env steps of the initial policy are "
            f"counted in each run's budget (give more timesteps, or a config with fewer "
            f"whiten_steps)"
        )
    if not isinstance(cfg.normalize, dict):
        raise ValueError(f"normalize must be a mapping, got {cfg.normalize!r}")
    if cfg.whiten_steps and (cfg.features is not None or cfg.normalize.get("norm_obs", False)):
        raise ValueError(
            "whiten_steps needs features: null and norm_obs: false (the "
            "trained actor takes the whitening into its first layer)"
        )
    if not isinstance(cfg.paired_loads, bool) or (cfg.paired_loads and not sb3):
        raise ValueError(
            f"paired_loads must be true or false, and true for the SB3 algorithms "
            f"only; got {cfg.paired_loads!r}"
        )
    if cfg.paired_loads and any(n % 2 for n in cfg.envs_per_load.values()):
        raise ValueError(
            f"paired_loads needs an even number of sub-envs per load case; n_envs "
            f"{cfg.n_envs} over loads {cfg.loads} gives {cfg.envs_per_load}"
        )
    if not isinstance(cfg.env_kwargs, dict):
        raise ValueError(f"env_kwargs must be a mapping of env options, got {cfg.env_kwargs!r}")
    if cfg.env_kwargs:
        for key, why in (
            ("observe_reward_scale", "vrs's actor reads the whole observation, log c included"),
            ("observe_commands", "vrs's exported actor has no memory of its commands"),
        ):
            if not sb3 and cfg.env_kwargs.get(key):
                raise ValueError(f"env_kwargs: {key} is for the SB3 algorithms ({why})")
        if "load_case" in cfg.env_kwargs:
            raise ValueError("env_kwargs: the training loads are the loads: field, not load_case")
        try:  # the training env's options, validated by the env's own config
            make_config(**cfg.env_kwargs)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"env_kwargs: {exc}") from None
    if cfg.residual not in RESIDUALS:
        raise ValueError(f"residual must be one of {list(RESIDUALS)}, got {cfg.residual!r}")
    check_headroom(cfg.action_headroom, "action_headroom")
    if cfg.action_headroom != 1.0 and not sb3:
        raise ValueError(
            "action_headroom is for the SB3 algorithms (vrs: a saturated linear actor)"
        )
    if cfg.shaping is not None:
        check_real("shaping", cfg.shaping, 0.0, 1e6, low_open=True)
    for name in SECTIONS:  # the sub-mappings, each validated by its dataclass
        value = getattr(cfg, name)
        if value is not None and not isinstance(value, dict):
            raise ValueError(f"{name} must be a mapping or null, got {value!r}")
        if value is not None:
            section(SECTIONS[name], value, name)
    if cfg.distill is not None and cfg.residual is not None:
        raise ValueError(
            "distill needs residual: null (the action's sign is the "
            f"voltage's), got residual {cfg.residual!r}"
        )
    if (cfg.residual or cfg.distill is not None) and cfg.env_kwargs.get("observe_commands"):
        raise ValueError(
            "env_kwargs: observe_commands cannot go with residual or distill (the LQR "
            "residual and the teacher read the env's own observation)"
        )
    if cfg.select is not None and cfg.normalize.get("norm_obs", False):
        raise ValueError(
            "select needs norm_obs: false (the chosen parameters would "
            "meet the final observation statistics)"
        )
    if not sb3 and (
        cfg.residual or cfg.shaping is not None or cfg.distill or cfg.select is not None
    ):
        raise ValueError("residual, shaping, distill and select are for the SB3 algorithms")
    if cfg.restarts > 1 and cfg.select is None:
        raise ValueError(
            f"restarts: {cfg.restarts} runs need select: (the choice between "
            "them is on the validation loads); got select: null"
        )
    check_model(cfg)
