"""Fuzz of the files the training commands read back (issue 65, deliverable 5): a results
table (``python -m train.core.report``), a config YAML (every command), a trial record and a
references cache (``python -m train.benchmark --resume``), each mutated by deleting a field,
changing a field's type, or truncating the file. Every mutation must give the package's own
error (:class:`acld_gym.util.validate.DataFileError`, naming the file) or a correct result
(the tables render; the config builds; the resumed record summarizes), never another
exception.

Provenance: the mutations are the issue's (deletion, type change, truncation); the base files
are the committed ``studies/results-v1.json`` and recipes, and a trial record of the
shape :func:`train.core.trials.run_trial` writes.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from acld_gym.util.validate import DataFileError
from train.config import TrainConfig, read_config
from train.config_checks import check_buildable
from train.core.evaluate import CASES
from train.core.records import check_references, check_trial, read_json, read_results
from train.core.report import curves_figure, main, render_blocks, summarize

ROOT = Path(__file__).resolve().parents[2]
RESULTS = json.loads((ROOT / "studies/results-v1.json").read_text())
#: Values a field's type is changed to (JSON's kinds, and numbers a computation chokes on).
SWAPS = [None, True, "x", "", [], {}, [1, 2], {"a": 1}, 0, -1, 1.5, 1e308, math.nan, math.inf]
FUZZ = settings(
    max_examples=80,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


def paths(value, prefix=()) -> list[tuple]:
    """Every place in a JSON value (keys and list indices), depth first."""
    out = []
    if isinstance(value, dict):
        for k, v in value.items():
            out += [(*prefix, k), *paths(v, (*prefix, k))]
    elif isinstance(value, list):
        for i, v in enumerate(value):
            out += [(*prefix, i), *paths(v, (*prefix, i))]
    return out


def mutated(value, where: tuple, swap) -> object:
    """A copy of ``value`` with the field at ``where`` deleted (``swap`` is ``"delete"``)
    or replaced by ``swap``."""
    value = copy.deepcopy(value)
    parent = value
    for k in where[:-1]:
        parent = parent[k]
    if swap == "delete":
        del parent[where[-1]]
    else:
        parent[where[-1]] = swap
    return value


def mutation(base):
    """A strategy of ``(kind, text)``: the JSON of ``base`` with one field deleted or of
    another type, or truncated."""
    places = paths(base)
    text = json.dumps(base, indent=1)
    edit = st.tuples(st.sampled_from(places), st.sampled_from(["delete", *SWAPS])).map(
        lambda p: ("edit", json.dumps(mutated(base, *p), indent=1))
    )
    cut = st.integers(0, len(text) - 1).map(lambda n: ("truncate", text[:n]))
    return st.one_of(edit, cut)


# --- the results table ------------------------------------------------------------------
def test_the_committed_results_pass():
    assert read_results(ROOT / "studies/results-v1.json") == RESULTS


@FUZZ
@given(m=mutation(RESULTS))
def test_a_mutated_results_file_is_refused_or_renders(tmp_path, m):
    path = tmp_path / "results.json"
    path.write_text(m[1])
    try:
        summary = read_results(path)
    except DataFileError as exc:
        assert str(exc).startswith(f"{path}: ")
        return
    blocks = render_blocks(summary)  # a file that passes renders every block
    assert all(isinstance(b, str) and b for b in blocks.values())


@settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck))
@given(m=mutation(RESULTS))
def test_a_mutated_results_file_that_passes_draws_its_figure(tmp_path, m):
    import matplotlib.pyplot as plt

    path = tmp_path / "results.json"
    path.write_text(m[1])
    try:
        summary = read_results(path)
    except DataFileError:
        return
    plt.close(curves_figure(summary))


@pytest.mark.parametrize(
    "where",
    [
        ("algorithms",),
        ("algorithms", "vrs", "per_seed"),
        ("algorithms", "vrs", "ise_rel_lqr", "random"),
        ("references", "lqr", "2"),
        ("episodes", "random"),
    ],
)
def test_the_report_command_names_the_field(tmp_path, capsys, where):
    path = tmp_path / "results.json"
    path.write_text(json.dumps(mutated(RESULTS, where, "delete")))
    with pytest.raises(SystemExit) as exit_:
        main([str(path)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert str(path) in err and ".".join(map(str, where)) in err and "Traceback" not in err


def test_empty_algorithms_and_per_seed_are_refused(tmp_path):
    for where, empty in ((("algorithms",), {}), (("algorithms", "vrs", "per_seed"), [])):
        path = tmp_path / "r.json"
        path.write_text(json.dumps(mutated(RESULTS, where, empty)))
        with pytest.raises(DataFileError, match="expected a non-empty list|at least one"):
            read_results(path)


def test_deep_nesting_and_binary_files_are_refused(tmp_path):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 200_000 + "]" * 200_000)
    binary = tmp_path / "bin.json"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    for path in (deep, binary):
        with pytest.raises(DataFileError, match=str(path)):
            read_json(path)
    with pytest.raises(DataFileError, match="larger than 1000 bytes"):
        read_json(ROOT / "studies/results-v1.json", max_bytes=1000)


# --- configs -------------------------------------------------------------------------------
def _recipe(name: str) -> dict:
    data = read_config(name)[1]
    return {**data, "n_envs": min(data.get("n_envs", 16), 16)}  # a quick build, same sections


CONFIGS = {name: _recipe(name) for name in ("vrs", "ppo", "sac")}


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    name=st.sampled_from(sorted(CONFIGS)),
    data=st.data(),
)
def test_a_mutated_config_is_refused_or_builds(tmp_path, name, data):
    base = CONFIGS[name]
    places = paths(base)
    kind = data.draw(st.sampled_from(["edit", "truncate"]))
    if kind == "edit":
        where = data.draw(st.sampled_from(places))
        swap = data.draw(st.sampled_from(["delete", *SWAPS]))
        text = yaml.safe_dump(mutated(base, where, swap))
    else:
        full = yaml.safe_dump(base)
        text = full[: data.draw(st.integers(0, len(full) - 1))]
    path = tmp_path / "mutant.yaml"
    path.write_text(text)
    try:
        _, cfg_data = read_config(path)
    except DataFileError as exc:
        assert str(exc).startswith(f"{path}: ")
        return
    cfg = TrainConfig.from_dict(cfg_data)
    # what the commands read before training: the label, the budget, the sections
    assert cfg.budget >= cfg.timesteps >= 1 and isinstance(cfg.training, str)
    assert sum(cfg.envs_per_load.values()) >= 1
    for section in ("select_config", "distill_config"):
        getattr(cfg, section)
    try:
        check_buildable(cfg)
    except ValueError as exc:  # refused before any computing, naming the setting
        assert str(exc).startswith("model")


def test_a_vrs_config_with_an_unknown_model_key_is_refused_at_once(tmp_path):
    path = tmp_path / "vrs_typo.yaml"
    path.write_text("base: vrs\nmodel: {step_sise: 0.1}\n")
    with pytest.raises(
        DataFileError, match=r"vrs_typo.yaml: model: unknown key\(s\) \['step_sise'\]"
    ):
        read_config(path)
    path.write_text("base: vrs\nmodel: {n_directions: 2.5}\n")
    with pytest.raises(DataFileError, match="model.n_directions must be an integer"):
        read_config(path)


# --- resume records --------------------------------------------------------------------
def _ise(scale: float) -> dict:
    return {str(c): scale * (1 + i) * 1e-9 for i, c in enumerate(CASES)}


TRIAL_CONFIG = {**read_config("vrs")[1], "timesteps": 1000, "eval_points": 1}
TRIAL = {
    "name": "vrs",
    "config": TRIAL_CONFIG,
    "seed": 0,
    "env_id": "ACLDBeam-v1",
    "random_episodes": 2,
}
RECORD = {
    **TRIAL,
    "algo": "vrs",
    "command": "python -m train.benchmark --algos vrs --seeds 0",
    "budget": 1000,
    "steps": 1000,
    "train_seconds": 1.5,
    "train_cpu_seconds": 1.4,
    "wall_seconds": 2.0,
    "final_ise": _ise(0.9),
    "validation_cost": 0.5,
    "curve": [{"steps": 0, "ise": _ise(3.0)}, {"steps": 1000, "ise": _ise(0.9)}],
    "record": {"iterations": 2},
}
REFS = {
    "env_id": "ACLDBeam-v1",
    "episodes": {"1": [0], "2": [0], "3": [0], "random": [100000, 100001]},
    **{name: _ise(k) for name, k in (("passive", 4), ("lqr", 1), ("smc", 1.01), ("mpc", 0.8))},
    "bound": _ise(0.5),
    "validation_cost": {"passive": 1.0, "lqr": 0.53, "smc": 0.53},
}


@pytest.fixture(scope="module")
def resume_out(tmp_path_factory):
    """A benchmark output folder with RECORD's agent saved (a linear vrs actor)."""
    from train.core.search import LinearDirectionActor
    from train.core.trials import agent_dir, save_agent

    out = tmp_path_factory.mktemp("bench")
    policy = LinearDirectionActor(np.full(10, 0.01), features=None)
    save_agent(policy, RECORD, agent_dir(out, "vrs", 0))
    return out


def test_the_base_record_is_reused(resume_out):
    from train.benchmark import reusable
    from train.core.trials import trial_path

    path = trial_path(resume_out, "vrs", 0)
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(RECORD))
    assert reusable(path, TRIAL, resume_out) == json.loads(json.dumps(RECORD))


@FUZZ
@given(m=mutation(RECORD))
def test_a_mutated_trial_record_is_trained_again_or_reused_whole(resume_out, capsys, m):
    from train.benchmark import reusable
    from train.core.trials import trial_path

    path = trial_path(resume_out, "vrs", 0)
    path.parent.mkdir(exist_ok=True)
    path.write_text(m[1])
    capsys.readouterr()
    rec = reusable(path, TRIAL, resume_out)
    said = capsys.readouterr().out
    if rec is None:  # damaged: one line naming the file; another run's record: silently
        assert said == "" or (said.count("\n") == 1 and str(path) in said and "again" in said)
        if m[0] == "truncate":
            assert said
        return
    assert said == ""
    summary = summarize([rec], REFS)  # what the resumed command computes with it
    assert summary["algorithms"]["vrs"]["seeds"] == [0]
    assert render_blocks(summary)


def test_a_trial_whose_agent_no_longer_loads_is_trained_again(resume_out, tmp_path, capsys):
    import shutil

    from train.benchmark import reusable
    from train.core.trials import agent_dir, trial_path

    out = tmp_path / "out"
    shutil.copytree(resume_out, out)
    path = trial_path(out, "vrs", 0)
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(RECORD))
    meta = agent_dir(out, "vrs", 0) / "metadata.json"
    meta.write_text(meta.read_text()[:50])  # truncated
    assert reusable(path, TRIAL, out) is None
    said = capsys.readouterr().out
    assert said.count("\n") == 1 and "does not load" in said and "again" in said


@FUZZ
@given(m=mutation(REFS))
def test_a_mutated_references_file_is_refused_or_summarizes(tmp_path, m):
    path = tmp_path / "references-ACLDBeam-v1.json"
    path.write_text(m[1])
    try:
        refs = check_references(read_json(path), path)
    except DataFileError as exc:
        assert str(exc).startswith(f"{path}: ")
        return
    summary = summarize([check_trial(copy.deepcopy(RECORD), "t.json")], refs)
    assert render_blocks(summary)


def test_a_damaged_references_file_is_computed_again(tmp_path, monkeypatch, capsys):
    import train.core.evaluate as evaluate
    from train.benchmark import resumed_references

    calls = []

    def fake(env_id, cache, random_episodes, bound=True):
        calls.append(cache)
        return copy.deepcopy(REFS)

    monkeypatch.setattr(evaluate, "references", fake)
    path = tmp_path / "references-ACLDBeam-v1.json"
    path.write_text(json.dumps(REFS)[:100])
    assert resumed_references("ACLDBeam-v1", tmp_path, 2, True) == REFS
    said = capsys.readouterr().out
    assert said.count("\n") == 1 and str(path) in said and "again" in said
    assert calls == [None] and json.loads(path.read_text()) == REFS  # replaced whole
    assert resumed_references("ACLDBeam-v1", tmp_path, 2, True) == REFS
    assert calls == [None, path] and capsys.readouterr().out == ""  # intact: the cache


def test_a_config_of_nested_aliases_is_refused_before_it_is_expanded(tmp_path):
    """Nine lines of YAML aliases standing for 9**9 values (a "billion laughs")."""
    lines = ["a: &a [x, x, x, x, x, x, x, x, x]"]
    for prev, name in zip("abcdefgh", "bcdefghi", strict=True):
        lines.append(f"{name}: &{name} [{', '.join([f'*{prev}'] * 9)}]")
    path = tmp_path / "laughs.yaml"
    path.write_text("\n".join([*lines, "algo: vrs", "timesteps: 10"]) + "\n")
    with pytest.raises(DataFileError, match="more than 10000 values"):
        read_config(path)
