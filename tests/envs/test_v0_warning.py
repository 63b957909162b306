"""``ACLDBeam-v0`` is a level, not an outdated release: gymnasium's "out of date" warning
on ``gym.make`` of it is not shown (acld_gym.envs.registration.OUT_OF_DATE), and the
filter is that narrow: another deprecation warning still is."""

import subprocess
import sys

SCRIPT = """
import warnings
import gymnasium as gym
import acld_gym
gym.make("ACLDBeam-v0").close()
warnings.warn("another deprecation", DeprecationWarning)
"""


def test_making_v0_says_nothing_about_an_upgrade():
    run = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "out of date" not in run.stderr
    assert "another deprecation" in run.stderr  # shown from __main__, as Python's default
