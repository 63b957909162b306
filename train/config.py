"""The one training configuration: a YAML file per recipe under ``train/recipes/``
(``ppo.yaml``, ``sac.yaml``, ``vrs.yaml``, the opt-in DAgger starts; a file of your own may
be ``base: ppo`` and what it changes, :func:`read_config`; the research record's variants
are in ``studies/ablations/``, not packaged), validated into a
:class:`TrainConfig`. ``python -m train`` and ``python -m train.benchmark`` read the same
files, build the same env (:func:`train.vec.make_vec_env`), train with the same function
(:func:`train.core.algos.train_algo`) and evaluate with the same evaluator
(:mod:`train.core.evaluate`).

This module reads the files (:func:`read_config`: a recipe's name or a path, its ``base:``
applied); the pieces live by job: the algorithms in :mod:`train.config_algos`, the schema
in :mod:`train.config_schema`, its checks in :mod:`train.config_validate` and
:mod:`train.config_model`, the sub-mappings in :mod:`train.config_sections`, the safe YAML
reader in :mod:`train.config_yaml`; every name is importable from here as before."""

from __future__ import annotations

from pathlib import Path

from acld_gym.physics.loads import parse_load_case
from acld_gym.util.validate import DataFileError

from .config_algos import ALGOS, SB3_ALGOS, algo_class
from .config_schema import TrainConfig
from .config_sections import SelectConfig
from .config_validate import RESIDUALS
from .config_yaml import read_yaml

__all__ = [
    "ALGOS",
    "SB3_ALGOS",
    "CONFIG_DIR",
    "TrainConfig",
    "SelectConfig",
    "algo_class",
    "config_path",
    "read_config",
    "load_config",
    "parse_load_case",
    "RESIDUALS",
]

#: The recipes: ``train/recipes/<name>.yaml``.
CONFIG_DIR = Path(__file__).resolve().parent / "recipes"


def config_path(spec: str | Path) -> Path:
    """The file of a config: a recipe name under ``train/recipes/`` (``"ppo"``) or a
    YAML path; ``FileNotFoundError`` naming both if there is none."""
    path = Path(spec)
    if not path.suffix:
        path = CONFIG_DIR / f"{spec}.yaml"
    if not path.is_file():
        raise FileNotFoundError(f"config {str(spec)!r}: file {str(path)!r} does not exist")
    return path


def _merged(base: dict, changes: dict) -> dict:
    """``base`` with ``changes`` applied key by key, nested mappings merged the same way."""
    out = dict(base)
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            value = _merged(out[key], value)
        out[key] = value
    return out


def _resolve(path: Path, seen: tuple[Path, ...] = ()) -> dict:
    """The mapping of a config file with its ``base:`` (a config name or a YAML path, itself
    resolved) applied: the base's settings, then the file's own on top of them. A name is
    the file ``<name>.yaml`` beside ``path`` if there is one (a chain of configs kept in one
    folder, e.g. ``studies/ablations/``), else a recipe's."""
    data = read_yaml(path)
    if "base" not in data:
        return data
    base = data.pop("base")
    if not isinstance(base, str):
        raise DataFileError(f"{path}: base: expected a config name or path, got {base!r}")
    sibling = path.parent / f"{base}.yaml"
    try:
        base_path = sibling if not Path(base).suffix and sibling.is_file() else config_path(base)
    except FileNotFoundError as exc:
        raise DataFileError(f"{path}: base: {exc}") from None
    if base_path.resolve() in seen:
        raise DataFileError(f"{path}: base: {base!r} leads back to itself")
    return _merged(_resolve(base_path, (*seen, path.resolve())), data)


def read_config(spec: str | Path) -> tuple[str, dict]:
    """``(name, mapping)`` of a config (:func:`config_path`), validated; the mapping is the
    file's own with its ``base:`` applied, if it names one (a variant of a recipe is
    ``base: ppo`` and the settings it changes; nested mappings such as ``model`` merge key
    by key). It is what a trial records and ``--resume`` compares. ``ValueError`` naming
    the file and the key on a malformed file or a bad value (a
    :class:`acld_gym.util.validate.DataFileError`)."""
    path = config_path(spec)
    data = _resolve(path)
    try:
        TrainConfig.from_dict(data)
    except (TypeError, ValueError) as exc:
        raise DataFileError(f"{path}: {exc}") from None
    return path.stem, data


def load_config(spec: str | Path) -> TrainConfig:
    """The validated :class:`TrainConfig` of a config (:func:`read_config`)."""
    return TrainConfig.from_dict(read_config(spec)[1])
