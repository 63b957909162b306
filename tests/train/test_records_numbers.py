"""A number beyond the float range in a benchmark file (results, references, a trial
record) is a DataFileError naming the file and the field, not an OverflowError (issue 65,
a second probe: 46 of 3000 mutations of results-v1.json)."""

import json
from pathlib import Path

import pytest

from acld_gym.util.validate import DataFileError
from train.core.records import check_references, check_results

RESULTS = Path(__file__).resolve().parents[2] / "studies" / "results-v1.json"
HUGE = 10**400


def test_a_huge_integer_in_results_is_named():
    data = json.loads(RESULTS.read_text())
    check_results(json.loads(RESULTS.read_text()), "r.json")  # the file as it is reads
    data["wall_seconds"] = HUGE
    with pytest.raises(DataFileError, match=r"r\.json: wall_seconds: expected a finite number"):
        check_results(data, "r.json")


def test_a_huge_integer_in_a_references_cache_is_named():
    ise = {"1": 1e-8, "2": 1e-8, "3": 1e-8, "random": 1e-8}
    refs = {"env_id": "ACLDBeam-v1", "episodes": {c: [0] for c in ise}}
    refs |= {n: dict(ise) for n in ("passive", "lqr", "smc", "mpc")}
    refs["validation_cost"] = {"lqr": 1.0}
    assert check_references(json.loads(json.dumps(refs)), "c.json", bound=False) == refs
    refs["smc"]["2"] = HUGE
    with pytest.raises(DataFileError, match=r"c\.json: smc\.2: expected a finite number"):
        check_references(refs, "c.json", bound=False)
