"""``studies/probes/probe.py``: the PPO probes' command line prints one JSON line per seed with
the probe's own arguments, and a run's line carries its settings, validation cost and ISE /
LQR per case as the benchmark's evaluation returns them."""

import json

import pytest

import train.core.evaluate as evaluate
import train.core.sb3_train as sb3_train
from studies.tests.probe_scripts import load_probe

probe = load_probe("probe")


def test_one_json_line_per_seed_with_the_probes_own_arguments(capsys):
    def add_arguments(p):
        p.add_argument("--hold", type=int, default=1000)

    def run(seed, args):
        return {"seed": seed, "hold": args.hold}

    assert (
        probe.seeds_main(
            "A probe.\n\nMore.", run, ["--seeds", "3", "7", "--hold", "64"], add_arguments
        )
        == 0
    )
    lines = capsys.readouterr().out.splitlines()
    assert [json.loads(x) for x in lines] == [{"seed": 3, "hold": 64}, {"seed": 7, "hold": 64}]
    with pytest.raises(SystemExit):  # an argument the probe does not take
        probe.seeds_main("A probe.", run, ["--noise", "linear"], add_arguments)


def test_a_runs_line_is_its_settings_and_its_evaluation(monkeypatch):
    calls = []

    def train(cfg, seed, env_id):
        calls.append((cfg, seed, env_id))
        return "policy", {"select": {"cost": 0.512345}}

    monkeypatch.setattr(sb3_train, "train_sb3", train)
    monkeypatch.setattr(evaluate, "ise_rel_lqr", lambda pol, env_id: {1: 0.84321, "random": 0.9571})
    line = probe.run_recipe("cfg", 5, "ACLDBeam-v1", hold=128)
    assert calls == [("cfg", 5, "ACLDBeam-v1")]
    assert list(line) == ["seed", "hold", "train_wall_s", "validation_cost_256", "ise_rel_lqr"]
    assert line["seed"] == 5 and line["hold"] == 128
    assert line["validation_cost_256"] == 0.5123
    assert line["ise_rel_lqr"] == {"1": 0.843, "random": 0.957}
