"""The recipes' retry thresholds (``restart_above``, :mod:`train.core.threshold`): relative
to the level's reference on the same validation loads, so they resolve on every registered
id; on ACLDBeam-v1 to the absolute costs the committed results were run with; a bare number
is refused on another level than the one it was calibrated on."""

import functools
import json
import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from acld_gym.envs.presets import PRESETS
from train.config import CONFIG_DIR, load_config
from train.core import threshold
from train.core.evaluate import validation_seeds
from train.core.threshold import ABSOLUTE_LEVEL, REFERENCES, RestartRule

LEVELS = sorted(PRESETS)  # every registered id
#: The recipes with several runs per seed and a retry threshold.
RETRYING = sorted(
    p.stem for p in CONFIG_DIR.glob("*.yaml") if load_config(p.stem).restart_above is not None
)


@functools.cache
def _cost(reference: str, env_id: str, loads: int) -> float:
    return threshold.reference_cost(reference, env_id, validation_seeds(loads))


def test_the_retrying_recipes_are_ppo_and_sac_and_relative_to_the_lqg():
    assert RETRYING == ["ppo", "sac"]
    for name in RETRYING:
        rule = RestartRule.parse(load_config(name).restart_above)
        assert rule.reference == "lqg", name  # no number calibrated on one level


@pytest.mark.parametrize("name", RETRYING)
@pytest.mark.parametrize("env_id", LEVELS)
def test_a_recipes_threshold_resolves_between_the_best_reference_and_passive(name, env_id):
    """On 16 validation loads (the recipes' own 256 and 64: the v1 test below; the rule and
    its resolution do not depend on the count)."""
    loads = 16
    got = RestartRule.parse(load_config(name).restart_above).resolve(
        env_id, validation_seeds(loads)
    )
    t = got["threshold"]
    costs = {ref: _cost(ref, env_id, loads) for ref in REFERENCES}
    assert got["reference_cost"] == costs["lqg"] and got["loads"] == loads
    assert math.isfinite(t) and min(costs["lqg"], costs["lqr"]) < t < costs["passive"], costs


@pytest.mark.parametrize("name", ["ppo", "sac"])
def test_on_v1_the_thresholds_are_the_absolute_ones_the_committed_results_ran_with(name):
    """The absolute ``restart_above`` the committed v1 results ran with (acld-gym
    0.18-0.19: 0.520 PPO, 0.540 SAC, read from ``studies/results-v1.json``), to well
    within the costs' round-off between machines (~3e-4): v1's results stay valid."""
    results = Path(__file__).resolve().parents[2] / "studies/results-v1.json"
    committed = json.loads(results.read_text())["algorithms"][name]["restart_above"]
    assert isinstance(committed, float)
    cfg = load_config(name)
    loads = validation_seeds(cfg.select_config.episodes)
    got = RestartRule.parse(cfg.restart_above).resolve(ABSOLUTE_LEVEL, loads)
    assert got["threshold"] == pytest.approx(committed, abs=2e-5)


def test_a_bare_number_is_the_calibrated_levels_only(monkeypatch):
    rule = RestartRule.parse(0.52)
    assert rule == RestartRule(0.52, None)
    monkeypatch.setattr(threshold, "reference_cost", lambda *a: pytest.fail("computed"))
    assert rule.resolve(ABSOLUTE_LEVEL, validation_seeds(3))["threshold"] == 0.52
    for env_id in set(LEVELS) - {ABSOLUTE_LEVEL}:
        with pytest.raises(ValueError, match=f"0.52 is an absolute validation cost.*on {env_id}"):
            rule.resolve(env_id, validation_seeds(3))
    RestartRule.parse("1.03 * lqg").check_level("ACLDBeamHard-v1")  # relative: every level


def test_a_bare_number_on_another_level_is_refused_before_training(tmp_path, capsys):
    from train.cli import main

    config = tmp_path / "mine.yaml"
    config.write_text("base: ppo\nrestart_above: 0.52\n")
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as exc:
        main(["ppo", "--config", str(config), "--env-id", "ACLDBeamLab-v1", "--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "restart_above: 0.52 is an absolute validation cost" in err and "'1.03 * lqg'" in err
    assert not out.exists()


@settings(max_examples=200, deadline=None)
@given(
    ratio=st.floats(min_value=1e-6, max_value=1e6, allow_nan=False),
    reference=st.sampled_from(REFERENCES),
    spaces=st.sampled_from(["{r} * {ref}", "{r}*{ref}", "  {r}  *  {ref} "]),
)
def test_relative_rules_parse_and_print_back(ratio, reference, spaces):
    rule = RestartRule.parse(spaces.format(r=repr(ratio), ref=reference))
    assert rule == RestartRule(ratio, reference)
    assert RestartRule.parse(str(rule)).reference == reference
    assert RestartRule.parse(str(rule)).ratio == pytest.approx(ratio, rel=1e-5)  # :g


@settings(max_examples=200, deadline=None)
@given(st.one_of(st.text(max_size=12), st.floats(), st.booleans(), st.none()))
def test_any_value_parses_or_is_named(value):
    try:
        rule = RestartRule.parse(value)
    except ValueError as exc:
        assert str(exc).startswith("restart_above")
        return
    if rule is None:
        assert value is None
    else:
        assert rule.ratio > 0 and math.isfinite(rule.ratio)
        assert rule.reference in (*REFERENCES, None)
