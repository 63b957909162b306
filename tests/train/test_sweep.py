"""train.sweep: the trial score (Ray itself is the optional extra)."""

import pytest

from train.sweep import score


def test_score_is_the_mean_over_the_thesis_cases():
    rec = {"final_ise": {"1": 1.0, "2": 4.0, "3": 9.0, "random": 100.0}}
    lqr = {"1": 2.0, "2": 4.0, "3": 6.0, "random": 1.0}
    assert score(rec, lqr) == pytest.approx((0.5 + 1.0 + 1.5) / 3)  # random is not scored


def test_score_needs_the_thesis_cases():
    with pytest.raises(ValueError, match="case"):
        score({"final_ise": {"1": 1.0}}, {"1": 1.0, "2": 1.0, "3": 1.0})


@pytest.mark.slow
def test_tune_sweep_runs_locally(tmp_path, capsys):
    pytest.importorskip("ray", reason="Ray Tune is the optional extra .[sweep]")
    from train.sweep import main

    assert (
        main(
            [
                "vrs",
                "--seeds",
                "0",
                "1",
                "--timesteps",
                "4000",
                "--num-cpus",
                "2",
                "--out",
                str(tmp_path),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "best:" in out and "ise_rel_lqr" in out
