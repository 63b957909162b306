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
from pathlib import Path

import pytest

_SESSION_TMP = tempfile.mkdtemp(prefix="acld-gym-tests-")
os.environ["TMPDIR"] = _SESSION_TMP  # subprocesses
tempfile.tempdir = _SESSION_TMP  # this process: tempfile.gettempdir(), pytest's tmp_path
os.environ.setdefault("ACLD_GYM_CACHE_DIR", os.path.join(_SESSION_TMP, "plant-cache"))
#: The session's folder shared by its xdist workers: the controller's (the workers inherit
#: its environment, so their plant cache above is the controller's too).
os.environ.setdefault("ACLD_GYM_TESTS_SHARED_TMP", _SESSION_TMP)
_mp_util.Finalize(
    None, shutil.rmtree, args=(_SESSION_TMP,), kwargs={"ignore_errors": True}, exitpriority=-1000
)

try:  # torch's default intra-op threads make small policies many times slower on few cores,
    import torch  # and far worse on a loaded machine (a plain SB3 test took 464 s, not 4 s):

    torch.set_num_threads(1)  # one, as the package's own training sets it
except ImportError:  # the core install has no torch
    pass


@pytest.fixture(scope="session")
def v1_references():
    """The references of ``python -m train.benchmark --no-bound --random-episodes 1`` on
    ACLDBeam-v1 (:func:`train.core.evaluate.references`: passive, LQR, SMC and MPC on the
    thesis cases and one held-out load, and the validation cost on 256 loads), written by
    the command's own cache writer into the session's shared folder: computed once per
    session (~3 s of CPU), by the first xdist worker that asks, and read back (its key
    checked) by the others. The tiny benchmarks of ``tests/train`` copy the file into
    their ``--out`` folder as ``references-ACLDBeam-v1.json``; the command checks its key
    and reads it back instead of computing it again (its MPC episodes and validation
    loads were most of each test's time)."""
    import fcntl

    from train.core.evaluate import references

    path = Path(os.environ["ACLD_GYM_TESTS_SHARED_TMP"]) / "references-ACLDBeam-v1.json"
    with open(path.with_suffix(".lock"), "w") as lock:  # a second worker waits, then reads
        fcntl.flock(lock, fcntl.LOCK_EX)
        references("ACLDBeam-v1", path, 1, bound=False)
    return path
