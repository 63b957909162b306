"""What the tests of ``benchmarks/*.py`` share: those scripts are files, not a package, so
a test loads one by path, with ``benchmarks/`` importable as it is for a script run as a
file (the scripts import their siblings, e.g. ``probe.py``)."""

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def load_script(name: str) -> ModuleType:
    """``benchmarks/<name>.py`` imported as the module ``name``."""
    if str(BENCHMARKS) not in sys.path:
        sys.path.insert(0, str(BENCHMARKS))
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def tiny_model(cfg, env_id: str = "ACLDBeam-v1", make_env=None):
    """The SB3 model of a probe's config ``cfg`` on 4 sub-envs with minibatches of 256,
    built and not trained, on the training env of ``make_env`` (the recipe's,
    :func:`train.vec.make_vec_env`, if None), and the training env's observation width."""
    import dataclasses

    import train.bench.sb3_train as sb3_train
    from train.vec import make_vec_env

    cfg = dataclasses.replace(cfg, n_envs=4, model={**cfg.model, "batch_size": 256})
    venv = (make_vec_env if make_env is None else make_env)(cfg, 0, env_id)
    try:
        return sb3_train.make_model(cfg, venv, 0), venv.observation_space.shape[0]
    finally:
        venv.close()
