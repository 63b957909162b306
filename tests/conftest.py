"""Test-session settings: everything a test session writes outside its ``tmp_path`` -- the
plants built during the tests (never in the user's ~/.cache), SB3's and other libraries'
temporary folders, subprocesses' files -- goes into one private folder per session (per
xdist worker), removed when the process exits: ``make test`` leaves nothing in /tmp.

The folder is removed by a :mod:`multiprocessing` finalizer of the lowest priority, after
multiprocessing's own (which removes its ``pymp-*`` folder inside it at exit): a removal at
session end would pull that folder from under it."""

import os
import shutil
import tempfile
from multiprocessing import util as _mp_util

_SESSION_TMP = tempfile.mkdtemp(prefix="acld-gym-tests-")
os.environ["TMPDIR"] = _SESSION_TMP  # subprocesses
tempfile.tempdir = _SESSION_TMP  # this process: tempfile.gettempdir(), pytest's tmp_path
os.environ.setdefault("ACLD_GYM_CACHE_DIR", os.path.join(_SESSION_TMP, "plant-cache"))
_mp_util.Finalize(
    None, shutil.rmtree, args=(_SESSION_TMP,), kwargs={"ignore_errors": True}, exitpriority=-1000
)
