"""``python -m train.ship OUT NAME --best CONFIG``: the shipping rule of docs/training.md (the
seed best on the thesis cases, mean ISE / LQR over cases 1-3) in code, and the shipped
``ppo`` and ``sac`` are the seeds it picks from the committed benchmark results."""

import json
import shutil

import pytest

from train.agent import TrainedAgent
from train.compare import AGENTS_DIR
from train.ship import best_seed, main

RESULTS = "studies/results-v1.json"


def _results(tmp_path, per_seed):
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "results.json").write_text(
        json.dumps({"algorithms": {"x": {"per_seed": per_seed}}})
    )
    return tmp_path


def test_the_lowest_mean_over_cases_1_to_3_wins_and_random_takes_no_part(tmp_path):
    out = _results(
        tmp_path,
        [
            {"seed": 0, "1": 0.80, "2": 0.95, "3": 1.00, "random": 0.90},  # mean 0.9167
            {"seed": 7, "1": 0.85, "2": 0.85, "3": 0.99, "random": 1.50},  # mean 0.8967: best
            {"seed": 3, "1": 0.90, "2": 0.90, "3": 0.99, "random": 0.50},
        ],
    )
    assert best_seed(out, "x") == 7


def test_equal_means_keep_the_first(tmp_path):
    row = {"1": 0.9, "2": 0.9, "3": 1.0, "random": 1.0}
    assert best_seed(_results(tmp_path, [{"seed": 4, **row}, {"seed": 2, **row}]), "x") == 4


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_shipped_agents_are_the_seeds_the_rule_picks(tmp_path, algo):
    shutil.copy(RESULTS, tmp_path / "results.json")
    agent = TrainedAgent.load(AGENTS_DIR / algo)
    assert agent.metadata["benchmark"] == algo
    assert agent.metadata["seed"] == best_seed(tmp_path, algo)


def test_bad_inputs_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="results.json"):
        best_seed(tmp_path, "sac")
    shutil.copy(RESULTS, tmp_path / "results.json")
    with pytest.raises(ValueError, match="config 'nope' is not in"):
        best_seed(tmp_path, "nope")
    bad = _results(tmp_path / "bad", [{"seed": 0, "1": 0.9, "2": 0.9}])  # no case 3
    with pytest.raises(ValueError, match=r"needs per_seed rows with \['seed', '1', '2', '3'\]"):
        best_seed(bad, "x")
    assert best_seed(tmp_path, "sac") == 1  # a well-formed file still reads


@pytest.mark.parametrize(
    "text, match",
    [
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ('{"algorithms": {', "not valid JSON"),
        (" " * (64 * 2**20 + 1), "larger than"),  # not read whole
    ],
)
def test_a_damaged_results_file_is_one_error_naming_it(tmp_path, text, match):
    (tmp_path / "results.json").write_text(text)
    with pytest.raises(ValueError, match=rf"{tmp_path / 'results.json'}: .*{match}"):
        best_seed(tmp_path, "sac")


def test_cli_ships_the_best_seed(tmp_path, capsys):
    out = _results(
        tmp_path / "bench",
        [
            {"seed": 0, "1": 0.9, "2": 0.9, "3": 1.0, "random": 1.0},
            {"seed": 1, "1": 0.8, "2": 0.9, "3": 1.0, "random": 1.0},
        ],
    )
    shutil.copytree(AGENTS_DIR / "vrs", out / "agents" / "x-s1")
    assert main([str(out), "mine", "--best", "x", "--agents", str(tmp_path / "agents")]) == 0
    assert "x: seed 1 is best on cases 1-3" in capsys.readouterr().out
    assert (
        TrainedAgent.load(tmp_path / "agents" / "mine").actor.arrays["W0"]
        == TrainedAgent.load(AGENTS_DIR / "vrs").actor.arrays["W0"]
    ).all()
    with pytest.raises(SystemExit):  # no agent directory for the chosen seed
        main([str(out), "mine", "--best", "y", "--agents", str(tmp_path / "agents")])
