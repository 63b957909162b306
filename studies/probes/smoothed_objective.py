"""The training objective as PPO sees it: smoothed by its own exploration noise.

PPO's gSDE explores with noise on the actor's gains, ``a = (W_u + eps)' u`` with ``eps ~ N(0,
diag sigma^2)`` in the whitened coordinates ``u = T' z``, so what it optimizes is the smoothed
cost :math:`J_\\sigma(W) = E_\\epsilon J(W + T \\epsilon)`, not the cost :math:`J(W)` of the
deterministic law it is evaluated with. This script trains a PPO recipe (``--config``: by
default ``ablation_ppo_independent``, acld-gym 0.8.0-0.14.0's, on which its numbers in
docs/training.md were measured, the run of ``python -m train ppo --config
studies/ablations/ablation_ppo_independent.yaml --seed S``; ``ppo`` for today's), reads its final
``sigma`` and whitening ``T``, and prints :math:`J_\\sigma` of the trained law and of the
shipped random-search law (``train/agents/vrs``) at fractions of that ``sigma``, on the same
validation loads and the same noise draws for both (common random numbers; one gain draw per
episode, where gSDE draws one per 64-step rollout). ``J`` is
:func:`train.core.evaluate.validation_cost`'s (the env's reward per load over the passive
beam's). Last it prints the cost of the trained law acting with its stochastic policy's
expected action, ``E[clip(mu + eps)]`` at the trained ``sigma`` (:class:`_MeanActionLaw`), the
other deterministic version of a clipped-Gaussian policy than the clipped mean the agents act
with. Not a test; takes about 2 min::

    python studies/probes/smoothed_objective.py --seed 0
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from probe import BASE, load_study_config  # studies/probes/probe.py


def linear_law(actor) -> tuple[np.ndarray, float]:
    """``(W, b)`` of an :class:`train.agent.ActorProgram` that is one linear layer on the
    observation, optionally clipped to [-1, 1] (``vrs``'s, or :func:`train.agent.export_sb3`
    of the PPO recipe's model): the voltage is ``120 clip(W' z + b, -1, 1)`` [V] (the env
    clips an unclipped actor at +/-120 V)."""
    kinds = [op["op"] for op in actor.ops]
    if kinds not in (["linear"], ["linear", "clip"]) or (
        kinds[-1] == "clip" and (actor.ops[1]["low"], actor.ops[1]["high"]) != (-1.0, 1.0)
    ):
        raise ValueError(f"actor: expected [linear] or [linear, clip(-1, 1)], got {actor.ops}")
    return (
        np.asarray(actor.arrays["W0"], float).ravel(),
        float(np.asarray(actor.arrays["b0"]).ravel()[0]),
    )


class _PerEpisodeLaw:
    """``predict`` of the law ``120 clip(W_n' z + b)`` with gains ``W`` (n, d), one row per
    sub-env of the vector env it runs in."""

    def __init__(self, W: np.ndarray, b: float):
        self.W, self.b = np.atleast_2d(W), b

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        a = np.einsum("ni,ni->n", np.asarray(obs, float), self.W) + self.b
        return 120.0 * np.clip(a, -1.0, 1.0)[:, None], state


class _MeanActionLaw:
    r"""``predict`` of the deterministic law that acts with the stochastic policy's expected
    action, :math:`120\,E[\mathrm{clip}(W'z + b + \epsilon' u, -1, 1)]` with
    :math:`\epsilon \sim N(0, \mathrm{diag}\,\sigma^2)` on the whitened :math:`u = T'z`:
    for :math:`X \sim N(\mu, s^2)`, :math:`\mu = W'z + b`, :math:`s^2 = \sum_i \sigma_i^2
    u_i^2`, :math:`E[\mathrm{clip}(X)] = -\Phi(\alpha) + 1 - \Phi(\beta) + \mu(\Phi(\beta) -
    \Phi(\alpha)) + s(\varphi(\alpha) - \varphi(\beta))`, :math:`\alpha = -(1 + \mu)/s`,
    :math:`\beta = (1 - \mu)/s` -- the other deterministic version of a clipped Gaussian
    policy than the clipped mean :math:`\mathrm{clip}(\mu)` the agents are evaluated with."""

    def __init__(self, W: np.ndarray, b: float, sigma: np.ndarray, T: np.ndarray):
        from scipy.stats import norm  # once, not per step

        self.W, self.b, self.var, self.T = np.ravel(W), b, np.ravel(sigma) ** 2, T
        self.norm = norm

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        z = np.atleast_2d(np.asarray(obs, float))
        mu = z @ self.W + self.b
        s = np.sqrt(((z @ self.T) ** 2) @ self.var) + 1e-300
        lo, hi = (-1.0 - mu) / s, (1.0 - mu) / s
        mean = (
            -self.norm.cdf(lo)
            + self.norm.sf(hi)
            + mu * (self.norm.cdf(hi) - self.norm.cdf(lo))
            + s * (self.norm.pdf(lo) - self.norm.pdf(hi))
        )
        return 120.0 * mean[:, None], state


def gain_noise_cost(W, b, dW, seeds, env_id: str = "ACLDBeam-v1") -> float:
    """:func:`train.core.evaluate.validation_cost` of the law ``(W + dW_n, b)`` on the
    random loads of ``seeds``, with the gain perturbation ``dW`` (n, d) of episode n (the
    episodes run side by side, sub-env n on load n)."""
    from train.core.evaluate import validation_cost

    seeds = [int(s) for s in seeds]
    dW = np.asarray(dW, float)
    if dW.shape != (len(seeds), np.size(W)):
        raise ValueError(f"dW: expected shape {(len(seeds), np.size(W))}, got {dW.shape}")
    return validation_cost(_PerEpisodeLaw(np.ravel(W)[None] + dW, b), env_id, seeds)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seed", type=int, default=0, help="the PPO recipe's seed")
    p.add_argument(
        "--config",
        default=BASE,
        help="the PPO recipe (studies/ablations/NAME.yaml or train/recipes/NAME.yaml; "
        "default 0.8.0-0.14.0's)",
    )
    p.add_argument("--loads", type=int, default=256, help="validation loads")
    p.add_argument("--draws", type=int, default=4, help="noise draws per load")
    p.add_argument(
        "--scales",
        type=float,
        nargs="+",
        default=[1.0, 0.5, 0.25],
        help="fractions of the trained sigma",
    )
    args = p.parse_args(argv)
    from train.agent import TrainedAgent, export_sb3
    from train.core.evaluate import validation_cost, validation_seeds
    from train.core.sb3_train import train_sb3

    pol, record = train_sb3(load_study_config(args.config), args.seed, "ACLDBeam-v1")
    T = np.asarray(record["transform"], float)
    sigma = np.exp(pol.model.policy.log_std.detach().numpy().ravel())
    laws = {
        f"ppo seed {args.seed}": linear_law(export_sb3(pol.model)),  # T folded in: on z
        "vrs (shipped)": linear_law(TrainedAgent.load("train/agents/vrs").actor),
    }
    seeds = validation_seeds(args.loads)
    rng = np.random.default_rng(12345)
    eps = rng.normal(size=(args.draws, len(seeds), sigma.size)) * sigma
    print(f"PPO's final gSDE sigma (whitened gains): {np.array2string(sigma, precision=3)}")
    print(
        f"J_sigma on {args.loads} validation loads x {args.draws} gain draws (lower is "
        f"better; 1 = passive)\n"
    )
    print("| sigma | " + " | ".join(laws) + " |")
    print("|---|" + "---|" * len(laws))
    zero = np.zeros((len(seeds), sigma.size))
    for scale in [0.0, *args.scales]:
        row = []
        for W, b in laws.values():
            draws = [zero] if scale == 0 else [scale * e @ T.T for e in eps]  # T eps per load
            row.append(np.mean([gain_noise_cost(W, b, dW, seeds) for dW in draws]))
        print(f"| {scale:g} x trained | " + " | ".join(f"{j:.4f}" for j in row) + " |")
    W, b = laws[f"ppo seed {args.seed}"]
    mean_law = validation_cost(_MeanActionLaw(W, b, sigma, T), "ACLDBeam-v1", seeds)
    print(
        f"\nppo seed {args.seed} acting with its expected clipped action at the trained sigma "
        f"(no noise): {mean_law:.5f}, against its clipped mean (the agent): row 0 above"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
