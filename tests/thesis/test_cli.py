"""Tests of acld_gym.thesis.cli: the ``reproduce`` and ``model`` subcommands.

Provenance: thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt sec. 2.7
(38 states), sec. 5.3 (passive case-1 peak 0.675 mm), sec. 5.5 (179 rad/s); the issue's
JSON row keys; argparse's convention of exit status 2 for usage errors.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from acld_gym.thesis.cli import main

KEYS = {"case", "controller", "saturation", "peak_mm", "settling_s", "max_voltage_V"}


@pytest.fixture(scope="module")
def model_json(tmp_path_factory):
    p = tmp_path_factory.mktemp("model") / "model.json"
    assert main(["model", "--json", str(p)]) == 0
    return json.loads(p.read_text())


@pytest.fixture(scope="module")
def reproduce_out(tmp_path_factory):
    base = tmp_path_factory.mktemp("repro")
    p = base / "sub" / "rows.json"  # parent directory created by the CLI
    plots = base / "figs"
    plots.mkdir()  # an old figure of a former run, which the run replaces (test_reproduce_plots)
    (plots / "hankel_singular_values.png").write_bytes(b"old")
    # A short window keeps this to a few seconds; the full run is tested in test_reproduce.
    assert (
        main(["reproduce", "--json", str(p), "--plots", str(plots), "--quiet", "--t-end", "0.1"])
        == 0
    )
    return json.loads(p.read_text()), plots


def test_model_json(model_json):
    out = model_json
    assert out["preset"] == "matlab"
    assert out["n_states"] == 38
    w = np.array(out["natural_frequencies_rad_s"])
    assert np.all(np.diff(w) >= 0)
    assert w[0] == pytest.approx(179.0, rel=0.01)
    h = np.array(out["hankel_singular_values"])
    assert h.size == 38
    assert np.all(np.diff(h) <= 0)
    assert out["passive_case1_peak_mm"] == pytest.approx(0.675, rel=0.02)


def test_model_preset_table1(tmp_path, model_json, capsys):
    p = tmp_path / "t1.json"
    assert main(["model", "--json", str(p), "--preset", "table1"]) == 0
    out = json.loads(p.read_text())
    assert out["preset"] == "table1"
    w0 = out["natural_frequencies_rad_s"][0]
    assert abs(w0 - model_json["natural_frequencies_rad_s"][0]) > 1e-3 * w0
    assert "preset table1" in capsys.readouterr().out


def test_reproduce_json(reproduce_out):
    rows, _ = reproduce_out
    assert len(rows) == 18
    for r in rows:
        assert set(r) == KEYS
    assert {(r["case"], r["controller"], r["saturation"]) for r in rows} == {
        (c, k, s) for c in (1, 2, 3) for k in ("passive", "lqr", "smc") for s in (True, False)
    }
    for r in rows:
        if r["saturation"] and r["controller"] != "passive":
            assert abs(r["max_voltage_V"] - 120.0) <= 1e-9


def test_reproduce_plots(reproduce_out):
    _, plots = reproduce_out
    files = {p.name for p in plots.glob("*.png")}
    expected = {
        f"case{c}_{k}_{s}.png"
        for c in (1, 2, 3)
        for k in ("passive", "lqr", "smc")
        for s in ("sat", "nosat")
    }
    expected |= {"hankel_singular_values.png", "frequency_response.png"}
    assert files == expected  # 20 distinct figures
    for name in files:  # the old figure among them replaced
        assert (plots / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "argv,word",
    [
        (["reproduce", "--t-end", "-1"], "--t-end"),
        (["reproduce", "--t-end", "abc"], "--t-end"),
        (["reproduce", "--t-end", "nan"], "--t-end"),
        (["reproduce", "--observer", "luenberger"], "--observer"),
        (["model", "--preset", "nope"], "--preset"),
        (["reproduce", "--preset", "nope"], "--preset"),
        (["frobnicate"], "frobnicate"),
        ([], "command"),
    ],
)
def test_bad_arguments(argv, word, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert word in err
    assert "Traceback" not in err


@pytest.mark.slow
def test_mesh_report_json(tmp_path):
    # The tables of docs/mesh.md come from this command.
    import json

    p = tmp_path / "mesh.json"
    assert main(["mesh", "--json", str(p)]) == 0
    rep = json.loads(p.read_text())
    conv, thesis = rep["plants"]["converged"], rep["plants"]["thesis"]
    assert max(abs(e) for e in conv["frequency_error"]) < 0.005
    assert conv["hinf_error_voltage"] < 0.01 and conv["hinf_error_load"] < 0.01
    assert thesis["frequency_error"][2] > 0.4  # mode 3 of the thesis mesh, +50 %
    assert conv["designs"]["8"]["hankel_gap"] > 2 * conv["designs"]["6"]["hankel_gap"]
