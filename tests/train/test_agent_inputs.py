"""TrainedAgent's inputs named in one line (issue 65, a second probe): an observation of
another width or rank, and metadata that is not a mapping."""

import numpy as np
import pytest

from train.agent import TrainedAgent, linear_program


@pytest.mark.parametrize("features", [None, "direction"])
@pytest.mark.parametrize("d", [3, 9])
def test_input_width_is_the_observation_width(d, features):
    actor = linear_program(np.arange(d + 2.0 if features else d + 1.0) / 10, features=features)
    assert actor.input_width == d
    assert actor(np.ones((2, d))).shape == (2, 1)


def test_an_observation_of_another_shape_is_refused_naming_it():
    agent = TrainedAgent.load("train/agents/ppo")
    width = agent.actor.input_width
    assert width == 9  # ACLDBeam-v1's estimate observation
    assert agent.predict(np.zeros(width))[0].shape == (1,)
    assert agent.predict(np.zeros((3, width)))[0].shape == (3, 1)
    for shape in [(width - 1,), (width + 1,), (1, 1, width), (2, width + 2), ()]:
        with pytest.raises(ValueError, match=rf"observation: expected shape \({width},\)"):
            agent.predict(np.zeros(shape))


def test_metadata_that_is_not_a_dict_is_a_type_error_naming_it():
    actor = linear_program(np.ones(4))
    with pytest.raises(TypeError, match="metadata: expected a dict, got NoneType"):
        TrainedAgent(actor, None)
