"""``studies/probes/law_average.py``: the mean of saturated linear laws is the law of the mean
gains, exactly; laws that do not act on the same observation alike, and anything but a
saturated linear law, are named; agents load in seed order; the script's figures for the
mean of identical laws are the law's own."""

import json

import numpy as np
import pytest

from studies.tests.probe_scripts import load_probe
from train.agent import TrainedAgent, linear_program

la = load_probe("law_average")
SHIPPED = TrainedAgent.load("train/agents/ppo")


def law(theta, name="law", **meta):
    return TrainedAgent(linear_program(np.asarray(theta)), {**SHIPPED.metadata, **meta}, name)


def test_the_mean_law_is_the_law_of_the_mean_gains():
    rng = np.random.default_rng(0)
    d = SHIPPED.actor.arrays["W0"].shape[0]
    thetas = [rng.normal(size=d + 1) for _ in range(3)]
    mean = la.mean_law([law(t) for t in thetas])
    z = rng.normal(size=(200, d)) * 3
    pre = np.mean([z @ t[:-1] + t[-1] for t in thetas], axis=0)
    assert np.abs(pre).max() > 1 and np.abs(pre).min() < 1  # both sides of saturation
    np.testing.assert_allclose(mean.actor(z).ravel(), np.clip(pre, -1, 1), rtol=0, atol=1e-12)
    one = la.mean_law([SHIPPED])  # an exported SB3 actor: one linear operation
    np.testing.assert_array_equal(one.actor(z), SHIPPED.actor(z))
    assert one.metadata == SHIPPED.metadata


def test_what_cannot_be_averaged_is_named():
    d = SHIPPED.actor.arrays["W0"].shape[0]
    with pytest.raises(ValueError, match="at least one agent"):
        la.mean_law([])
    other = law(np.ones(d + 1), "other", action_headroom=3.0)
    with pytest.raises(ValueError, match="'other' differs from 'law' in 'action_headroom'"):
        la.mean_law([law(np.zeros(d + 1)), other])
    direction = TrainedAgent(
        linear_program(np.zeros(d + 2), None, "direction"), SHIPPED.metadata, "dir"
    )
    with pytest.raises(ValueError, match="'dir' is not a saturated linear law"):
        la.mean_law([law(np.zeros(d + 1)), direction])


def test_cyclic_groups():
    assert la.cyclic_groups(4, 2) == [(0, 1), (1, 2), (2, 3), (3, 0)]
    assert la.cyclic_groups(3, 3) == [(0, 1, 2), (1, 2, 0), (2, 0, 1)]
    for k in (0, 4):
        with pytest.raises(ValueError, match="k must be between 1 and the number of agents 3"):
            la.cyclic_groups(3, k)


def test_the_script_reads_agents_in_seed_order_and_the_mean_of_one_law_twice_is_it(
    tmp_path, capsys
):
    for seed in (10, 2):
        SHIPPED.save(tmp_path / "out" / "agents" / f"ppo-s{seed}")
    agents = la.load_agents([tmp_path / "out"])
    assert [a.name for a in agents] == ["ppo-s2", "ppo-s10"]
    with pytest.raises(FileNotFoundError, match="has no agents"):
        la.load_agents([tmp_path / "out", tmp_path])
    SHIPPED.save(tmp_path / "out" / "agents" / "vrs-s3")
    with pytest.raises(ValueError, match=r"agents of \['ppo', 'vrs'\]; choose one"):
        la.load_agents([tmp_path / "out"])
    assert [a.name for a in la.load_agents([tmp_path / "out"], "vrs")] == ["vrs-s3"]
    assert la.main([str(tmp_path / "out"), "--algo", "ppo", "--k", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    groups = [json.loads(line) for line in lines[:2]]
    assert [g["laws"] for g in groups] == [["ppo-s2", "ppo-s10"], ["ppo-s10", "ppo-s2"]]
    assert lines[2].startswith("single IQM") and lines[3].startswith("mean of 2 IQM")
    assert lines[2].split("IQM")[1] == lines[3].split("IQM")[1]
    assert all(0.5 < v < 1.5 for v in groups[0]["ise_rel_lqr"])
