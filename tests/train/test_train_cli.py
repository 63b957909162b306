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


@pytest.mark.parametrize(
    "argv, word",
    [
        (["a2c"], "invalid choice"),
        ([], "algo"),
        (["ppo", "--timesteps", "-5"], "--timesteps"),
        (["ppo", "--timesteps", "abc"], "--timesteps"),
        (["sac", "--n-envs", "0"], "--n-envs"),
        (["ppo", "--load-case", "4"], "--load-case"),
        (["ppo", "--seed", "-1"], "--seed"),
        (["ppo", "--param-noise", "-0.1"], "--param-noise"),
        (["ppo", "--config", "/nonexistent/ppo.yaml"], "does not exist"),
        (["sac", "--config", "ppo_dagger"], "not 'sac'"),
        (["ppo", "--random-episodes", "0"], "--random-episodes"),
        (["ppo", "--env-id", "ACLDBeam-v9"], "--env-id"),
        (["ppo", "--backend", "ray"], "--backend"),
        (["sac", "--cpus", "0"], "--cpus"),
    ],
)
def test_train_cli_bad_input(argv, word, capsys):
    _exit2(train_main, argv, capsys, word)


def test_train_cli_bad_config_values(tmp_path, capsys):
    bad = tmp_path / "ppo.yaml"
    bad.write_text(
        "algo: ppo\ntimesteps: 10\nn_envs: 2\nresidual: pid\nmodel: {policy: MlpPolicy}\n"
    )
    _exit2(train_main, ["ppo", "--config", str(bad)], capsys, "residual")


@pytest.mark.parametrize(
    "argv, word",
    [
        (["--only", "nope"], "does not exist"),
        (["--random-episodes", "-1"], "--random-episodes"),
        (["--param-noise", "-1"], "--param-noise"),
    ],
)
def test_compare_cli_bad_input(argv, word, capsys):
    _exit2(compare_main, argv, capsys, word)


@pytest.mark.parametrize(
    "argv, word",
    [
        (["dqn"], "invalid choice"),
        (["ppo", "--timesteps", "0"], "--timesteps"),
        (["ppo", "--num-cpus", "0"], "--num-cpus"),
        (["ppo", "--seeds", "-1"], "--seeds"),
    ],
)
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


def test_ship_cli_bad_input(tmp_path, capsys, monkeypatch):
    from train.ship import main as ship_main

    monkeypatch.chdir(tmp_path)  # the default destination is ./agents

    _exit2(ship_main, [str(tmp_path), "ppo"], capsys, "lacks")
    (tmp_path / "policy.npz").write_bytes(b"not an npz")
    (tmp_path / "metadata.json").write_text("{}")
    _exit2(ship_main, [str(tmp_path), "ppo"], capsys, str(tmp_path))
    _exit2(ship_main, [str(tmp_path), "../x"], capsys, "name")
