"""Weight averaging of the policy (``TrainConfig.average``): the uniform and the exponential
average of the iterates, a context that lends the average and gives the iterate back, and a
run whose returned actor is the average of its iterates."""

import numpy as np
import pytest
import torch

from tests.train.tiny_sb3 import LinearModel as _Model
from tests.train.tiny_sb3 import tiny_sac, tiny_sac_recipe
from train.bench.sb3_train import Averaging
from train.config import TrainConfig


def _cfg(**average):
    return tiny_sac(average=average or None)


def test_uniform_average_from_start():
    avg, model = Averaging(_cfg(start=100)), _Model()
    for steps, value in ((50, 1000.0), (100, 1.0), (200, 2.0), (300, 6.0)):
        model.set(value)
        avg.update(steps, model)  # the iterate before start stays out
    model.set(-5.0)
    with avg.applied(model):
        assert torch.allclose(model.policy.weight, torch.full((1, 2), 3.0))
        assert torch.allclose(model.policy.bias, torch.full((1,), -3.0))
    assert torch.equal(model.policy.weight, torch.full((1, 2), -5.0))  # the iterate back
    rec = avg.apply(model)
    assert rec == {"start": 100, "halflife": None, "iterates": 3}
    assert torch.allclose(model.policy.weight, torch.full((1, 2), 3.0))


def test_exponential_average_halves_an_iterate_per_halflife():
    avg, model = Averaging(_cfg(start=0, halflife=100)), _Model()
    model.set(0.0)
    avg.update(0, model)
    model.set(1.0)
    avg.update(100, model)  # one half-life later: weight 1/2
    avg.apply(model)
    assert model.policy.weight[0, 0].item() == pytest.approx(0.5)
    model.set(1.0)
    avg.update(300, model)  # two half-lives: the old average keeps 1/4
    avg.apply(model)
    assert model.policy.weight[0, 0].item() == pytest.approx(0.25 * 0.5 + 0.75)


def test_averaging_off_or_not_started_leaves_the_model_alone():
    for avg in (Averaging(_cfg()), Averaging(_cfg(start=10**6))):
        model = _Model()
        model.set(2.0)
        avg.update(10, model)
        with avg.applied(model):
            assert torch.equal(model.policy.weight, torch.full((1, 2), 2.0))
        assert avg.apply(model) is None
        assert torch.equal(model.policy.weight, torch.full((1, 2), 2.0))


@pytest.mark.parametrize(
    "bad, match",
    [
        ({"start": -1}, "average.start"),
        ({"start": 0, "halflife": 0}, "average.halflife"),
        ({"begin": 0}, "average: unknown key"),
    ],
)
def test_bad_average_configs_are_refused_by_name(bad, match):
    with pytest.raises(ValueError, match=match):
        _cfg(**bad)
    with pytest.raises(ValueError, match="average must be a mapping"):
        TrainConfig(algo="sac", timesteps=10, model={"policy": "MlpPolicy"}, average=3)
    with pytest.raises(ValueError, match="for the SB3 algorithms"):
        TrainConfig(algo="vrs", timesteps=10, features=None, average={"start": 0})


def test_a_run_returns_the_average_of_its_iterates(monkeypatch):
    """A tiny SAC run of the recipe with averaging from step 0: the returned actor's gains
    are the mean of the actor's gains at every rollout end (recorded independently here),
    folded with the whitening as the recipe's are."""
    from train.bench import sb3_train

    seen = []
    update = sb3_train.Averaging.update

    def spy(self, steps, model):
        if self.config is not None and steps >= self.config.start:
            seen.append(
                {k: v.detach().clone().double() for k, v in model.policy.state_dict().items()}
            )
        update(self, steps, model)

    monkeypatch.setattr(sb3_train.Averaging, "update", spy)
    cfg = tiny_sac_recipe(600, select=None, restarts=1, average={"start": 300})
    policy, record = sb3_train.train_sb3(cfg, 0, "ACLDBeam-v1")
    assert record["average"]["iterates"] == len(seen) > 10
    key = next(k for k in seen[0] if k.startswith("actor.mu") and k.endswith("weight"))
    mean = torch.stack([s[key] for s in seen]).mean(0)
    assert not torch.allclose(mean, seen[0][key])  # the iterates moved: a real average
    T = torch.as_tensor(np.array(record["transform"]))
    folded = policy.model.policy.state_dict()[key].double()
    assert torch.allclose(folded, mean @ T.T, rtol=1e-5, atol=1e-7)
