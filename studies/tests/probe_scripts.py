"""What the tests of the research probes (``studies/probes/*.py``) share: a probe loaded by
path (:func:`load_probe`, with ``studies/probes/`` importable for its ``import probe``) and
a probe's SB3 model built small (:func:`tiny_model`)."""

from pathlib import Path
from types import ModuleType

from tests.benchmark_scripts import load_script

PROBES = Path(__file__).resolve().parents[1] / "probes"


def load_probe(name: str) -> ModuleType:
    """``studies/probes/<name>.py`` imported as the module ``name``."""
    return load_script(name, PROBES)


def tiny_model(cfg, env_id: str = "ACLDBeam-v1", make_env=None):
    """The SB3 model of a probe's config ``cfg`` on 4 sub-envs with minibatches of 256,
    built and not trained, on the training env of ``make_env`` (the recipe's,
    :func:`train.vec.make_vec_env`, if None), and the training env's observation width."""
    import dataclasses

    import train.core.sb3_train as sb3_train
    from train.vec import make_vec_env

    cfg = dataclasses.replace(cfg, n_envs=4, model={**cfg.model, "batch_size": 256})
    venv = (make_vec_env if make_env is None else make_env)(cfg, 0, env_id)
    try:
        return sb3_train.make_model(cfg, venv, 0), venv.observation_space.shape[0]
    finally:
        venv.close()
