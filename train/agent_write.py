"""Writing an agent folder whole: built in a temporary sibling and swapped in with one
rename (:func:`acld_gym.util.atomic.replace_dir`), so a reader, or a disk that fills
midway, sees the old agent or the new one, never new weights under old metadata; and the
check, made before anything is computed, that a folder may be replaced so
(:func:`check_replaceable`). Reading is :mod:`train.agent_files`'s."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from acld_gym.util.atomic import replace_dir, strict_json

from .agent_schema import parse_metadata

__all__ = ["REPLACEABLE", "check_replaceable", "write_folder"]

#: The files an existing folder may hold for :func:`write_folder` to replace it: an agent's
#: and a training run's (``python -m train`` writes ``trial.json`` beside the agent; older
#: runs kept SB3's pickles).
REPLACEABLE = frozenset(
    {
        "policy.npz",
        "metadata.json",
        "learning_curve.csv",
        "trial.json",
        "model.zip",
        "vecnormalize.pkl",
    }
)


def check_replaceable(path: str | Path) -> Path:
    """``path`` (absolute) if :func:`write_folder` may put an agent there: it does not
    exist, or is an agent's or a run's folder (only :data:`REPLACEABLE` files and hidden
    ones, such as a desktop's ``.DS_Store``; no folder), and is not the working directory
    or one holding it. ``ValueError`` naming it otherwise: call it
    before computing anything."""
    path = Path(os.path.abspath(path))
    if not path.name or path == Path(path.anchor):
        raise ValueError(f"{str(path)!r} cannot be an agent folder")
    if not os.path.lexists(path):
        return path
    if path.is_symlink():
        return path  # replaced by the folder, its target untouched
    if not path.is_dir():
        raise ValueError(f"{str(path)!r} exists and is not a directory")
    cwd = Path.cwd().resolve()
    if cwd == path.resolve() or path.resolve() in cwd.parents:
        raise ValueError(f"{str(path)!r} holds the working directory; it cannot be replaced")
    with os.scandir(path) as entries:
        other = sorted(
            e.name
            for e in entries
            if e.is_dir(follow_symlinks=False)
            or not (e.name in REPLACEABLE or e.name.startswith("."))
        )
    if other:
        raise ValueError(
            f"{str(path)!r} holds {[n[:40] for n in other][:5]} besides an agent's files; "
            "an agent replaces its folder whole: choose a new or an agent's folder"
        )
    return path


def write_folder(
    path: str | Path, arrays: dict[str, np.ndarray], meta: dict, texts: dict[str, str]
) -> Path:
    """Put an agent folder at ``path`` whole (module docstring): ``policy.npz`` with
    ``arrays``, ``metadata.json`` with ``meta`` (non-finite numbers as null) and each text
    file of ``texts``; the folder's previous content is gone, or, if anything fails, left
    as it was. ``ValueError`` if :func:`check_replaceable` refuses ``path``; an
    :class:`train.agent_schema.AgentFileError` if ``meta`` would not load
    (:func:`parse_metadata`), before anything is written."""
    path = check_replaceable(path)
    for name in texts:
        if name in ("policy.npz", "metadata.json") or Path(name).name != name:
            raise ValueError(f"{name!r} is not an extra file name of an agent folder")
    meta_text = json.dumps(strict_json(meta), indent=2, allow_nan=False) + "\n"
    parse_metadata(meta_text.encode(), str(path / "metadata.json"))  # write only what loads

    def fill(tmp: Path) -> None:
        with open(tmp / "policy.npz", "wb") as fh:
            np.savez(fh, **arrays)
        (tmp / "metadata.json").write_text(meta_text, encoding="utf-8")
        for name, text in texts.items():
            (tmp / name).write_text(text, encoding="utf-8")

    return replace_dir(path, fill)
