"""``studies/probes/actor_steps.py``: the linear law's parameters are a param group of their own
with the probe's eps, step scale and decoupled weight decay, whose steps are Adam's (AdamW's
with a decay) with the learning rate times that scale; every other parameter keeps the
recipe's Adam; bad values are named."""

import pytest
import torch

from studies.tests.probe_scripts import load_probe, tiny_model

acs = load_probe("actor_steps")


def test_scaled_adam_steps_a_group_as_adam_with_its_learning_rate_scaled():
    torch.manual_seed(0)
    a, b = torch.nn.Parameter(torch.randn(3)), torch.nn.Parameter(torch.randn(2))
    a2, b2 = (torch.nn.Parameter(p.detach().clone()) for p in (a, b))
    opt = acs.ScaledAdam([{"params": [a]}, {"params": [b], "eps": 0.1, "lr_scale": 7.0}], lr=1e-2)
    ref_a = torch.optim.Adam([a2], lr=1e-2)
    ref_b = torch.optim.Adam([b2], lr=7e-2, eps=0.1)
    for _ in range(3):
        for o in (opt, ref_a, ref_b):
            o.zero_grad()
        ((a * torch.arange(3.0)).sum() + (b**2).sum()).backward()
        ((a2 * torch.arange(3.0)).sum() + (b2**2).sum()).backward()
        opt.step()
        ref_a.step()
        ref_b.step()
    assert torch.allclose(a, a2, rtol=0, atol=1e-7) and torch.allclose(b, b2, rtol=0, atol=1e-7)
    assert [g["lr"] for g in opt.param_groups] == [1e-2, 1e-2]  # the schedule's, restored


def test_a_decayed_group_steps_as_adamw():
    torch.manual_seed(1)
    a = torch.nn.Parameter(torch.randn(4))
    a2 = torch.nn.Parameter(a.detach().clone())
    group = {"params": [a], "weight_decay": 0.3, "decoupled_weight_decay": True, "lr_scale": 2.0}
    opt = acs.ScaledAdam([group], lr=1e-2)
    ref = torch.optim.AdamW([a2], lr=2e-2, weight_decay=0.3)
    for _ in range(4):
        for o, p in ((opt, a), (ref, a2)):
            o.zero_grad()
            (p * torch.arange(4.0)).sum().backward()
            o.step()
    assert torch.allclose(a, a2, rtol=0, atol=1e-7)
    assert not torch.allclose(a, a2 + 1e-5)  # the comparison can fail


def test_the_law_is_its_own_group_and_the_rest_keeps_the_recipe():
    model, _ = tiny_model(acs.config(eps=0.2, lr_scale=5.0, weight_decay=0.01))
    pol = model.policy
    rest, law = pol.optimizer.param_groups
    assert [id(p) for p in law["params"]] == [id(p) for p in pol.action_net.parameters()]
    assert law["eps"] == 0.2 and law["lr_scale"] == 5.0
    assert law["weight_decay"] == 0.01 and law["decoupled_weight_decay"]
    assert rest["weight_decay"] == 0 and not rest["decoupled_weight_decay"]
    assert "lr_scale" not in rest and rest["eps"] == pol.optimizer_kwargs["eps"] == 1e-5  # SB3's
    every = {id(p) for p in pol.parameters()}
    assert {id(p) for g in (rest, law) for p in g["params"]} == every
    assert any(p is pol.log_std for p in rest["params"])  # gSDE's log std: the recipe's


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"eps": 0.0}, "actor_eps"),
        ({"lr_scale": -1.0}, "actor_lr_scale"),
        ({"weight_decay": -0.1}, "actor_weight_decay"),
    ],
)
def test_bad_values_are_named(kwargs, name):
    with pytest.raises(ValueError, match=name):
        tiny_model(acs.config(**kwargs))
