"""``train.sb3_save``: an SB3 run kept whole (the model and its ``VecNormalize``), each file
written atomically, the folder checked before training."""

from __future__ import annotations

import argparse
import pickle

import pytest

from train.sb3_save import MODEL_FILE, STATS_FILE, arg_save_dir, save_run


class _Model:
    """What ``save_run`` uses of an SB3 algorithm: ``save(file)`` and its ``VecNormalize``."""

    def __init__(self, payload: bytes, stats=None, fail: bool = False):
        self.payload, self.stats, self.fail = payload, stats, fail

    def save(self, fh) -> None:
        fh.write(self.payload[:3])
        if self.fail:
            raise OSError(28, "No space left on device")
        fh.write(self.payload[3:])

    def get_vec_normalize_env(self):
        return self.stats


def test_save_run_writes_both_files_and_a_failed_save_keeps_the_old(tmp_path):
    folder = tmp_path / "new" / "run"
    assert save_run(_Model(b"model one", stats={"mean": [1.0]}), folder) == folder
    assert (folder / MODEL_FILE).read_bytes() == b"model one"
    assert pickle.loads((folder / STATS_FILE).read_bytes()) == {"mean": [1.0]}
    with pytest.raises(OSError, match="No space"):
        save_run(_Model(b"model two", fail=True), folder)
    assert (folder / MODEL_FILE).read_bytes() == b"model one"  # not a truncated "mod"
    assert sorted(p.name for p in folder.iterdir()) == [MODEL_FILE, STATS_FILE]  # no temp left
    save_run(_Model(b"no stats"), tmp_path / "plain")  # trained without VecNormalize
    assert [p.name for p in (tmp_path / "plain").iterdir()] == [MODEL_FILE]


def test_arg_save_dir_refuses_a_folder_where_a_file_must_go(tmp_path):
    assert arg_save_dir(str(tmp_path / "fresh")) == str(tmp_path / "fresh")
    (tmp_path / "run" / MODEL_FILE).mkdir(parents=True)
    with pytest.raises(argparse.ArgumentTypeError) as err:
        arg_save_dir(str(tmp_path / "run"))
    assert str(err.value).endswith(f": its {MODEL_FILE} is a folder")
    with pytest.raises(argparse.ArgumentTypeError, match="is not a folder"):
        arg_save_dir("/dev/null/x")
