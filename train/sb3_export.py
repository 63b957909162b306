"""An SB3 model's deterministic actor as an :class:`train.agent.ActorProgram` (numpy arrays
and a JSON list of operations), so that a trained policy is saved as data
(:func:`export_sb3`), and the walk over its layers that export and whitening share
(:func:`actor_parts`). Needs torch and stable-baselines3 (imported when called); re-exported by
:mod:`train.agent`."""

from __future__ import annotations

from typing import Any

import numpy as np

from .agent_program import ActorProgram

__all__ = ["actor_extractor", "actor_parts", "export_sb3"]


def actor_extractor(model):
    """The features extractor of an SB3 model's deterministic actor (what
    :func:`actor_parts` returns first), whatever the layers after it."""
    pol = model.policy
    actor = getattr(pol, "actor", None)
    if actor is not None:  # SAC, TQC, CrossQ, TD3
        return actor.features_extractor
    if hasattr(pol, "mlp_extractor"):  # PPO / A2C
        return pol.pi_features_extractor
    return pol.features_extractor  # ARS (sb3-contrib)


def actor_parts(model) -> tuple[Any, list, bool]:
    """The deterministic actor of an SB3 model as ``(features extractor, layers in order,
    squash)``: ``squash`` is True where SB3 applies a tanh after the last layer. One walk
    for :func:`export_sb3` and for folding a whitening into the first linear layer
    (:func:`train.core.sb3_train.fold_whitening`)."""
    import torch.nn as nn  # torch is slow to import: only an SB3 model's export needs it

    pol = model.policy
    extractor = actor_extractor(model)
    actor = getattr(pol, "actor", None)
    if actor is not None and hasattr(actor, "latent_pi"):  # SAC, TQC, CrossQ: tanh(mu(latent))
        mu = actor.mu
        layers = [*actor.latent_pi, *(mu if isinstance(mu, nn.Sequential) else [mu])]
        return extractor, layers, True
    if actor is not None and hasattr(actor, "mu"):  # TD3: mu is the whole net, Tanh last
        return extractor, list(actor.mu), False
    if not hasattr(pol, "mlp_extractor"):  # ARS (sb3-contrib): action_net is the actor
        return extractor, list(pol.action_net), False
    # PPO / A2C: Gaussian mean, clipped to the box
    return extractor, [*pol.mlp_extractor.policy_net, pol.action_net], bool(pol.squash_output)


def export_sb3(model, obs_norm=None) -> ActorProgram:
    """The deterministic actor of an SB3 ``MlpPolicy`` (PPO, SAC, TD3, TQC, CrossQ, ARS,
    ...) and its ``VecNormalize`` observation statistics as an
    :class:`train.agent.ActorProgram` (equal to SB3's ``predict`` to float32 round-off;
    tests/train/test_distill.py and, for CrossQ's batch renormalisation,
    tests/train/test_benchmark.py)."""
    # torch and stable-baselines3 (train.features too) are slow to import: only an export
    import torch.nn as nn
    from stable_baselines3.common.torch_layers import FlattenExtractor

    from .features import DirectionFeatures, DropLast

    ops: list[dict] = []
    arrays: dict[str, np.ndarray] = {}
    if obs_norm is not None and getattr(obs_norm, "norm_obs", False):
        ops.append(
            {"op": "normalize", "clip": float(obs_norm.clip_obs), "eps": float(obs_norm.epsilon)}
        )
        arrays["mean"] = obs_norm.obs_rms.mean.copy()
        arrays["var"] = obs_norm.obs_rms.var.copy()
    extractor, layers, squash = actor_parts(model)
    if isinstance(extractor, DirectionFeatures):
        ops.append({"op": "direction"})
    elif isinstance(extractor, DropLast):  # an asymmetric agent: the actor never read the
        pass  # appended log(reward scale), and the deployed env does not append it
    elif not isinstance(extractor, FlattenExtractor):
        raise TypeError(
            f"export_sb3 supports the flatten or direction features only, got "
            f"{type(extractor).__name__}"
        )
    layer = 0
    for m in layers:
        if isinstance(m, nn.Linear):
            arrays[f"W{layer}"] = m.weight.detach().double().numpy().T.copy()
            arrays[f"b{layer}"] = m.bias.detach().double().numpy().copy()
            ops.append({"op": "linear", "layer": layer})
            layer += 1
        elif _is_batch_renorm(m):  # CrossQ's; in eval mode an affine map of each feature
            w, b = _batch_renorm_affine(m)
            arrays[f"W{layer}"] = np.diag(w)
            arrays[f"b{layer}"] = b
            ops.append({"op": "linear", "layer": layer})
            layer += 1
        elif isinstance(m, nn.Tanh):
            ops.append({"op": "tanh"})
        elif isinstance(m, nn.ReLU):
            ops.append({"op": "relu"})
        elif isinstance(m, nn.Hardtanh):
            ops.append({"op": "clip", "low": float(m.min_val), "high": float(m.max_val)})
        else:
            raise TypeError(f"export_sb3: unsupported layer {m!r}")
    if squash:
        ops.append({"op": "tanh"})
    return ActorProgram(ops, arrays)


def _is_batch_renorm(m) -> bool:
    """Whether ``m`` is sb3-contrib's ``BatchRenorm`` (CrossQ's layers)."""
    try:  # sb3-contrib is optional (and imports torch)
        from sb3_contrib.common.torch_layers import BatchRenorm
    except ImportError:  # sb3-contrib not installed: no BatchRenorm to meet
        return False
    return isinstance(m, BatchRenorm)


def _batch_renorm_affine(m) -> tuple[np.ndarray, np.ndarray]:
    r"""The per-feature map :math:`x \mapsto w x + b` of sb3-contrib's ``BatchRenorm`` in
    evaluation mode, as SB3's ``predict`` runs it: :math:`w = \gamma / \sqrt{\sigma^2 +
    \epsilon}`, :math:`b = \beta - w \mu` with the running mean :math:`\mu` and variance
    :math:`\sigma^2` (``ra_mean``, ``ra_var``) and the affine ``scale`` :math:`\gamma` and
    ``bias`` :math:`\beta` (1 and 0 if not ``affine``)."""

    def arr(t):
        return t.detach().double().numpy().copy()

    mean, var = arr(m.ra_mean), arr(m.ra_var)
    gamma, beta = (arr(m.scale), arr(m.bias)) if m.affine else (1.0, 0.0)
    w = np.broadcast_to(gamma / np.sqrt(var + float(m.eps)), mean.shape).copy()
    return w, np.broadcast_to(beta, mean.shape) - w * mean
