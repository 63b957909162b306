r"""Initialise an agent's actor by imitating a reference policy (DAgger).

The constrained MPC is within a few percent of the clairvoyant bound but solves a
QP every millisecond; PPO and SAC from scratch stayed near LQR on this beam
(docs/training.md). Distillation gives the actor MPC-class control to
start from; reinforcement learning then fine-tunes it on the env's reward.

This is DAgger (Ross, Gordon & Bagnell 2011): in iteration i the training env is
driven by the teacher with probability :math:`\beta_i` per step and by the
current actor otherwise; every visited state is labelled by the teacher, and the
actor is refitted on all labels so far.

The MPC saturates in most steps, so the label is the *sign* of the teacher's
voltage, :math:`s = \pm 1`, and the fit is logistic regression of the actor's
(pre-clip, pre-tanh) mean m on it,

.. math:: \min \frac1N \sum_i \log\left(1 + e^{-s_i m(z_i)}\right),

solved with full-batch L-BFGS (the directions of the states are strongly
correlated, and first-order steps converge slowly). On separable data the
weights grow until few states sit in the linear band :math:`|m| < 1`: the
actor becomes a switching law with a thin boundary layer, like the teacher.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from acld_gym.physics.actuator import V_LIMIT
from baselines.evaluate import default_policies

__all__ = ["DistillConfig", "actor_mean", "distill", "fit_sign", "TEACHERS"]

#: Reference policies that can serve as teacher (``baselines.policies``).
TEACHERS = ("mpc", "smc", "lqr")


@dataclass(frozen=True)
class DistillConfig:
    """DAgger settings (the ``distill`` mapping of a training YAML file).

    Attributes
    ----------
    teacher : str
        Reference policy imitated: ``"mpc"`` (default), ``"smc"`` or ``"lqr"``.
    iterations : int
        DAgger iterations; each runs one 1 s episode in every sub-env.
    beta : float
        Teacher's share of the actions in the first iteration (in [0, 1]).
    beta_decay : float
        Factor on the teacher's share per iteration (in [0, 1]); with more than one
        iteration the last one is driven by the actor alone.
    max_iter : int
        L-BFGS iterations of each fit.
    """

    teacher: str = "mpc"
    iterations: int = 6
    beta: float = 1.0
    beta_decay: float = 0.5
    max_iter: int = 300

    def __post_init__(self):
        if self.teacher not in TEACHERS:
            raise ValueError(
                f"distill.teacher must be one of {list(TEACHERS)}, got {self.teacher!r}"
            )
        for name in ("iterations", "max_iter"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"distill.{name} must be a positive integer, got {value!r}")
        for name in ("beta", "beta_decay"):
            value = getattr(self, name)
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float))
                or not 0.0 <= value <= 1.0
            ):
                raise ValueError(f"distill.{name} must be a number in [0, 1], got {value!r}")

    def betas(self) -> list[float]:
        """Teacher's share per iteration: geometric, the last one 0 (the actor alone)."""
        b = [self.beta * self.beta_decay**i for i in range(self.iterations)]
        if self.iterations > 1:
            b[-1] = 0.0
        return b

    def as_dict(self) -> dict:
        return asdict(self)


def actor_mean(model):
    """``(f, params, squash)``: the actor's mean (before PPO's clipping or SAC's tanh)
    as a torch function of the (normalized) observation, its parameters, and
    whether the action is ``tanh`` of it (SAC) rather than the mean clipped (PPO)."""
    from stable_baselines3 import SAC  # slow to import (torch): the config imports this module

    pol = model.policy
    if isinstance(model, SAC):
        actor = pol.actor

        def f(obs):
            mean, _, _ = actor.get_action_dist_params(obs)
            return mean[:, 0]

        return f, [*actor.latent_pi.parameters(), *actor.mu.parameters()], True

    def f(obs):
        latent = pol.mlp_extractor.forward_actor(pol.pi_features_extractor(obs))
        return pol.action_net(latent)[:, 0]

    params = [*pol.mlp_extractor.policy_net.parameters(), *pol.action_net.parameters()]
    return f, params, bool(pol.squash_output)


def fit_sign(f, params, x, s, max_iter: int = 300) -> float:
    """Logistic regression of ``f(x)`` on the signs ``s`` (full-batch L-BFGS, in
    place); returns the final mean loss."""
    import torch  # slow to import: the config imports this module (DistillConfig)

    opt = torch.optim.LBFGS(
        params,
        lr=1.0,
        max_iter=max_iter,
        history_size=20,
        line_search_fn="strong_wolfe",
        tolerance_grad=1e-9,
        tolerance_change=1e-12,
    )

    def closure():
        opt.zero_grad()
        loss = torch.nn.functional.softplus(-s * f(x)).mean()
        loss.backward()
        return loss

    opt.step(closure)
    with torch.no_grad():
        return float(torch.nn.functional.softplus(-s * f(x)).mean())


def distill(model, venv, cfg: DistillConfig, seed: int = 0, log=None) -> list[dict]:
    r"""Fit ``model``'s actor to ``cfg.teacher`` by DAgger in ``venv`` (in place).

    ``venv`` is the training env of :func:`train.vec.make_vec_env` (``VecNormalize``
    over, somewhere inside, :class:`train.vec.VecAgentEnv`, whose voltage map must be the
    plain :math:`V = 120 a`, so that the action's sign is the voltage's). The teacher sees
    the env's raw observation (:attr:`train.vec.VecAgentEnv.last_obs`), the actor what the
    training env gives it. Observation statistics, if normalized, keep updating, and all
    labels are normalized with the latest ones before each fit. Returns one dict per
    iteration: ``beta``, ``labels`` (so far), ``loss`` and ``agreement`` (fraction of this
    iteration's states where the refitted actor's voltage has the teacher's sign).
    """
    # torch and train.vec (SB3) are slow to import: the config imports this module
    import torch

    from .vec import VecAgentEnv, find_wrapper

    agent_env = find_wrapper(venv, VecAgentEnv)
    if agent_env is None:
        raise ValueError(
            "distill needs the training env of train.vec.make_vec_env "
            "(no VecAgentEnv inside the given env)"
        )
    if agent_env.residual is not None:
        raise ValueError(
            "distill needs the plain voltage map (residual: null), got "
            f"residual {agent_env.residual!r}"
        )
    teacher = default_policies()[cfg.teacher]
    f, params, squash = actor_mean(model)
    rng = np.random.default_rng(seed)
    steps = int(venv.get_attr("horizon", [0])[0])  # one episode per sub-env and iteration
    raw_all: list[np.ndarray] = []
    sign_all: list[np.ndarray] = []
    history = []
    obs = venv.reset()
    for it, beta in enumerate(cfg.betas()):
        raw_it, sign_it = [], []
        for _ in range(steps):
            raw = venv.get_original_obs()  # the actor's input before normalization
            volts, _ = teacher.predict(agent_env.last_obs)
            with torch.no_grad():
                m = f(torch.as_tensor(obs, dtype=torch.float32)).numpy()
            student = np.tanh(m) if squash else np.clip(m, -1.0, 1.0)
            use = rng.random(len(raw)) < beta
            action = np.where(use, volts[:, 0] / V_LIMIT, student)
            raw_it.append(raw.copy())
            sign_it.append(np.where(volts[:, 0] >= 0.0, 1.0, -1.0))
            obs, _, _, _ = venv.step(action[:, None].astype(np.float32))
        raw_all += raw_it
        sign_all += sign_it
        x = torch.as_tensor(venv.normalize_obs(np.concatenate(raw_all)), dtype=torch.float32)
        s = torch.as_tensor(np.concatenate(sign_all), dtype=torch.float32)
        loss = fit_sign(f, params, x, s, cfg.max_iter)
        with torch.no_grad():
            m_it = f(
                torch.as_tensor(venv.normalize_obs(np.concatenate(raw_it)), dtype=torch.float32)
            ).numpy()
        agree = float(np.mean(np.where(m_it >= 0.0, 1.0, -1.0) == np.concatenate(sign_it)))
        rec = {
            "iteration": it,
            "beta": round(beta, 6),
            "labels": int(len(x)),
            "loss": round(loss, 6),
            "agreement": round(agree, 4),
        }
        history.append(rec)
        if log is not None:
            log(rec)
    return history
