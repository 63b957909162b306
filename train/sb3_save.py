"""Keep an SB3 run whole: the model and its ``VecNormalize`` statistics in one folder, each
file written atomically (a temporary file, then a rename: a reader or a full disk sees the
old file or the new one, never a truncated one), the folder checked when the command line
is parsed (:func:`arg_save_dir`). The guide's scripts (``docs/examples/sb3_*.py``) save
through it; :func:`train.scoring.score` scores what it saved
(``vec_normalize=<folder>/vecnormalize.pkl``)."""

from __future__ import annotations

import argparse
import pickle
from pathlib import Path

from acld_gym.util.atomic import write_atomic
from acld_gym.util.validate import arg_dir

__all__ = ["MODEL_FILE", "STATS_FILE", "arg_save_dir", "save_run"]

#: The model, as SB3's ``save`` writes it (``PPO.load`` / ``SAC.load`` read it).
MODEL_FILE = "model.zip"
#: The ``VecNormalize`` statistics, as its ``save`` writes them (``VecNormalize.load``).
STATS_FILE = "vecnormalize.pkl"


def arg_save_dir(text: str) -> str:
    """An argparse ``type=`` for :func:`save_run`'s folder: a folder that can hold files
    (:func:`acld_gym.util.validate.arg_dir`) where neither file's name is taken by a
    folder, so that a run is never trained to be lost at its save."""
    arg_dir(text)
    for name in (MODEL_FILE, STATS_FILE):
        if (Path(text) / name).is_dir():
            raise argparse.ArgumentTypeError(
                f"expected a folder that can hold files, got {text!r}: its {name} is a folder"
            )
    return text


def save_run(model, folder: str | Path) -> Path:
    """Write ``model`` (an SB3 algorithm) to ``folder/model.zip`` and, if it trained through
    ``VecNormalize``, its statistics to ``folder/vecnormalize.pkl``, each atomically; the
    folder is made if needed. Returns the folder."""
    folder = Path(folder)
    write_atomic(folder / MODEL_FILE, model.save)
    stats = model.get_vec_normalize_env()
    if stats is not None:  # what VecNormalize.save writes: the wrapper, its venv left out
        write_atomic(folder / STATS_FILE, lambda fh: pickle.dump(stats, fh))
    return folder
