"""A probe of the PPO recipe (acld-gym 0.15.0) for the stretch goal: the actor's gains take
steps of one size in every direction of the whitened observation, as the random search's
do, instead of Adam's steps, which are about the learning rate in size per coordinate.

The recipe's Adam divides each coordinate's step by that coordinate's gradient RMS, so
the linear law's gains move at the same speed along directions whose gradients differ
by a factor of 14 (gradient RMS 0.003-0.046 per gain in an exploratory 1M-step run of
the recipe). In the flat
valley of near-optimal laws the end point depends on that metric; the random search's
update, isotropic in the same whitened coordinates, ends at another trade between cases
1 and 2. Here the gains (``action_net``: the law's weights and bias) are an Adam param
group of their own with ``eps`` far above their gradients' RMS, so their steps are the
learning rate times ``lr_scale / eps`` times the gradient's running mean: momentum SGD,
the same in every direction. ``lr_scale`` (default 7) keeps the median gain's step near
Adam's. The critic and gSDE's log std keep the recipe's Adam. One run per seed.

``--weight-decay W`` adds a decoupled weight decay to the law's group (AdamW's): a pull of
the law towards the least-norm law of the flat valley. With ``--eps 1e-5 --lr-scale 1``
(SB3's Adam) that is the only change to the recipe (``--weight-decay 0`` gave the recipe's
seed 0 to the printed digits: validation cost 0.5147, ISE / LQR 0.834 on case 1)::

    python studies/probes/actor_steps.py --seeds 0 1 2 3 4 --eps 1e-5 --lr-scale 1 \\
        --weight-decay 0.03

It prints one JSON line per seed (``studies/probes/probe.py``). Not a test; about half a
minute per seed on two cores; the isotropic steps::

    python studies/probes/actor_steps.py --seeds 0 1 2 3 4

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table).
"""

from __future__ import annotations

import sys

import torch
from probe import one_run, run_recipe, seeds_main  # studies/probes/probe.py, beside this script

from acld_gym.util.validate import check_real
from train.core.sb3_policies import AsymmetricCriticPolicy


class ScaledAdam(torch.optim.Adam):
    """Adam whose param groups may carry ``lr_scale``: a group's step uses its learning
    rate times that (SB3 sets every group's ``lr`` from the schedule)."""

    def step(self, closure=None):
        saved = [group["lr"] for group in self.param_groups]
        for group in self.param_groups:
            group["lr"] = group["lr"] * group.get("lr_scale", 1.0)
        try:
            return super().step(closure)
        finally:
            for group, lr in zip(self.param_groups, saved, strict=True):
                group["lr"] = lr


class IsotropicActorPolicy(AsymmetricCriticPolicy):
    """The recipe's policy whose law (``action_net``) is a :class:`ScaledAdam` param group
    with ``actor_eps``, ``actor_lr_scale`` and a decoupled ``actor_weight_decay`` (AdamW's;
    0: none); every other parameter keeps the recipe's Adam."""

    def __init__(
        self,
        *args,
        actor_eps: float = 0.1,
        actor_lr_scale: float = 7.0,
        actor_weight_decay: float = 0.0,
        **kwargs,
    ):
        self.actor_eps = check_real("actor_eps", actor_eps, 0.0, low_open=True)
        self.actor_lr_scale = check_real("actor_lr_scale", actor_lr_scale, 0.0, low_open=True)
        self.actor_weight_decay = check_real("actor_weight_decay", actor_weight_decay, 0.0)
        super().__init__(*args, **kwargs)

    def law_parameters(self) -> list:
        """The linear law's weights and bias (not gSDE's log std)."""
        return list(self.action_net.parameters())

    def _build(self, lr_schedule) -> None:
        super()._build(lr_schedule)
        law = self.law_parameters()
        ids = {id(p) for p in law}
        rest = [p for p in self.parameters() if id(p) not in ids]
        group = {
            "params": law,
            "eps": self.actor_eps,
            "lr_scale": self.actor_lr_scale,
            "weight_decay": self.actor_weight_decay,
            "decoupled_weight_decay": True,
        }
        self.optimizer = ScaledAdam(
            [{"params": rest}, group], lr=lr_schedule(1), **self.optimizer_kwargs
        )


def config(eps: float = 0.1, lr_scale: float = 7.0, weight_decay: float = 0.0):
    """``train/recipes/ppo.yaml``'s config with :class:`IsotropicActorPolicy`, one run."""
    kwargs = {"actor_eps": eps, "actor_lr_scale": lr_scale, "actor_weight_decay": weight_decay}
    return one_run(IsotropicActorPolicy, kwargs, base="ppo")


def main(argv: list[str] | None = None) -> int:
    def add_arguments(p):
        p.add_argument("--eps", type=float, default=0.1, help="the law's Adam eps (0.1)")
        p.add_argument("--lr-scale", type=float, default=7.0, help="its step scale (7)")
        p.add_argument(
            "--weight-decay", type=float, default=0.0, help="its decoupled weight decay (0)"
        )

    return seeds_main(
        __doc__,
        lambda seed, a: run_recipe(
            config(a.eps, a.lr_scale, a.weight_decay),
            seed,
            actor_eps=a.eps,
            actor_lr_scale=a.lr_scale,
            actor_weight_decay=a.weight_decay,
        ),
        argv,
        add_arguments,
    )


if __name__ == "__main__":
    sys.exit(main())
