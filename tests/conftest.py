"""Test-session settings: everything a test session writes outside its ``tmp_path`` -- the
plants built during the tests (never in the user's ~/.cache), SB3's and other libraries'
temporary folders, subprocesses' files -- goes into one private folder per session (per
xdist worker), which the session removes when it ends: ``make test`` leaves nothing in
/tmp."""

import os
import shutil
import tempfile

_SESSION_TMP = tempfile.mkdtemp(prefix="acld-gym-tests-")
os.environ["TMPDIR"] = _SESSION_TMP  # subprocesses
tempfile.tempdir = _SESSION_TMP  # this process: tempfile.gettempdir(), pytest's tmp_path
os.environ.setdefault("ACLD_GYM_CACHE_DIR", os.path.join(_SESSION_TMP, "plant-cache"))


def pytest_sessionfinish(session, exitstatus):
    shutil.rmtree(_SESSION_TMP, ignore_errors=True)
