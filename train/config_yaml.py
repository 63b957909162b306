"""Reading one training config file as YAML, safely: :class:`UniqueKeyLoader` (a key given
twice is refused), :func:`check_size` (at most :data:`MAX_VALUES` values, aliases expanded)
and :func:`read_yaml`, the mapping of one file or a :class:`DataFileError` naming the file
and the place."""

from __future__ import annotations

from pathlib import Path

import yaml

from acld_gym.util.validate import DataFileError

__all__ = ["MAX_VALUES", "MAX_BYTES", "UniqueKeyLoader", "check_size", "read_yaml"]

#: The most values (every list item and mapping entry, YAML aliases counted each time they
#: are used) and bytes a config file may hold; a recipe has under 100 values and 3 kB.
MAX_VALUES = 10_000
MAX_BYTES = 2**20


class UniqueKeyLoader(yaml.SafeLoader):
    """YAML's safe loader that refuses a key given twice in one mapping (plain YAML keeps the
    last silently: ``timesteps: 1000`` then ``timesteps: 2000`` would train 2000)."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":  # '<<': merged keys may be replaced
                    continue
                key = self.construct_object(key_node, deep=deep)
                try:
                    duplicate = key in seen
                    seen.add(key)
                except TypeError:  # an unhashable key: the base class refuses it
                    continue
                if duplicate:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"key {key!r} given twice", key_node.start_mark
                    )
        return super().construct_mapping(node, deep)


def check_size(data, path) -> None:
    """``ValueError`` naming ``path`` if the parsed config ``data`` holds more than
    :data:`MAX_VALUES` values, YAML aliases expanded (a few lines of nested aliases can
    stand for billions of values, which comparing or recording the config would build)."""
    stack, count = [data], 0
    while stack:
        value = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise ValueError(f"{path}: more than {MAX_VALUES} values (aliases expanded)")
        if isinstance(value, dict):
            stack += [*value.keys(), *value.values()]
        elif isinstance(value, list):
            stack += value


def read_yaml(path: Path) -> dict:
    """The mapping of one YAML file; :class:`DataFileError` naming the file and the place."""
    try:
        if path.stat().st_size > MAX_BYTES:
            raise DataFileError(f"{path}: larger than {MAX_BYTES} bytes: not a config")
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=UniqueKeyLoader) or {}  # noqa: S506 (a safe loader)
        check_size(data, path)
    except (yaml.YAMLError, UnicodeDecodeError, RecursionError) as exc:
        where = getattr(exc, "problem_mark", None)
        at = f" (line {where.line + 1}, column {where.column + 1})" if where else ""
        why = getattr(exc, "problem", None) or type(exc).__name__
        raise DataFileError(f"{path}: not valid YAML{at}: {why}") from None
    except ValueError as exc:
        raise DataFileError(str(exc)) from None
    if not isinstance(data, dict):
        raise DataFileError(f"{path}: expected a mapping of settings, got {type(data).__name__}")
    return data
