"""train.sweep: the trial score (Ray itself is the optional extra)."""

import pytest

from train.sweep import score_run


def test_score_is_the_mean_of_the_last_evaluation(tmp_path):
    (tmp_path / "learning_curve.csv").write_text(
        "timesteps,case,ise,ise_rel_lqr,peak_mm,tip_rms_mm,max_voltage_V\n"
        "10,1,1,2.0,0,0,0\n10,2,1,2.0,0,0,0\n10,3,1,2.0,0,0,0\n"
        "20,1,1,0.5,0,0,0\n20,2,1,1.0,0,0,0\n20,3,1,1.5,0,0,0\n")
    assert score_run(tmp_path) == pytest.approx(1.0)


def test_score_needs_an_evaluation(tmp_path):
    (tmp_path / "learning_curve.csv").write_text(
        "timesteps,case,ise,ise_rel_lqr,peak_mm,tip_rms_mm,max_voltage_V\n")
    with pytest.raises(ValueError, match="no evaluation"):
        score_run(tmp_path)
