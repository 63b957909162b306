"""Test-session settings: plants built during the tests are cached in a temporary
directory, never in the user's ~/.cache."""

import os
import tempfile

os.environ.setdefault("ACLD_GYM_CACHE_DIR", tempfile.mkdtemp(prefix="acld-gym-test-cache-"))
