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


@pytest.mark.slow
def test_tune_sweep_runs_locally(tmp_path, capsys):
    pytest.importorskip("ray", reason="Ray Tune is the optional extra .[sweep]")
    from train.sweep import main

    assert main(["ppo", "--seeds", "0", "1", "--timesteps", "4096", "--eval-freq", "2048",
                 "--num-cpus", "2", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "best:" in out and "ise_rel_lqr" in out
