"""Bad input to the training, comparison and sweep CLIs: a clear message and exit
status 2, never a traceback."""

import pytest

from train.cli import main as train_main
from train.compare import main as compare_main
from train.sweep import main as sweep_main


def _exit2(fn, argv, capsys, word):
    with pytest.raises(SystemExit) as e:
        fn(argv)
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err
    return err


@pytest.mark.parametrize("argv, word", [
    (["a2c"], "invalid choice"),
    ([], "algo"),
    (["ppo", "--timesteps", "-5"], "--timesteps"),
    (["ppo", "--timesteps", "abc"], "--timesteps"),
    (["sac", "--n-envs", "0"], "--n-envs"),
    (["ppo", "--load-case", "4"], "--load-case"),
    (["ppo", "--seed", "-1"], "--seed"),
    (["ppo", "--param-noise", "-0.1"], "--param-noise"),
    (["ppo", "--config", "/nonexistent/ppo.yaml"], "does not exist"),
    (["ppo", "--backend", "ray"], "--backend"),
])
def test_train_cli_bad_input(argv, word, capsys):
    _exit2(train_main, argv, capsys, word)


def test_train_cli_bad_config_values(tmp_path, capsys):
    bad = tmp_path / "ppo.yaml"
    bad.write_text("n_timesteps: 10\nn_envs: 2\nresidual: pid\nmodel: {policy: MlpPolicy}\n")
    _exit2(train_main, ["ppo", "--config", str(bad)], capsys, "residual")


@pytest.mark.parametrize("argv, word", [
    (["--only", "nope"], "does not exist"),
    (["--random-episodes", "-1"], "--random-episodes"),
    (["--param-noise", "-1"], "--param-noise"),
])
def test_compare_cli_bad_input(argv, word, capsys):
    _exit2(compare_main, argv, capsys, word)


@pytest.mark.parametrize("argv, word", [
    (["dqn"], "invalid choice"),
    (["ppo", "--timesteps", "0"], "--timesteps"),
    (["ppo", "--num-cpus", "0"], "--num-cpus"),
    (["ppo", "--seeds", "-1"], "--seeds"),
])
def test_sweep_cli_bad_input(argv, word, capsys):
    _exit2(sweep_main, argv, capsys, word)


def test_sweep_without_ray_says_how_to_install(capsys, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_ray(name, *args, **kwargs):
        if name == "ray" or name.startswith("ray."):
            raise ImportError("no ray")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_ray)
    _exit2(sweep_main, ["ppo"], capsys, "[sweep]")


def test_ship_cli_bad_input(tmp_path, capsys):
    from train.ship import main as ship_main

    _exit2(ship_main, [str(tmp_path), "ppo"], capsys, "lacks")
    _exit2(ship_main, [str(tmp_path), "../x"], capsys, "name")


def test_best_timesteps_follows_the_eval_ranking(tmp_path):
    """The lowest mean ISE / LQR over the thesis cases; the first of equal ones."""
    from train.ship import best_timesteps

    head = "timesteps,case,ise,ise_rel_lqr,peak_mm,tip_rms_mm,max_voltage_V\n"
    rows = [(0, 1, 0.5), (0, 2, 0.5), (100, 1, 0.4), (100, 2, 0.5), (200, 1, 0.5),
            (200, 2, 0.4)]
    curve = tmp_path / "learning_curve.csv"
    curve.write_text(head + "".join(f"{t},{c},0,{r},0,0,0\n" for t, c, r in rows))
    assert best_timesteps(curve) == 100
    curve.write_text(head)
    with pytest.raises(ValueError, match="empty"):
        best_timesteps(curve)
