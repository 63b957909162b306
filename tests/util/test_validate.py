"""acld_gym.util.validate: numbers beyond the float range are refused in one short line."""

import gymnasium as gym
import pytest

import acld_gym  # noqa: F401
from acld_gym.util.validate import check_real, shown


@pytest.mark.parametrize("value", [10**400, -(10**400)])
def test_an_integer_beyond_floats_is_a_value_error_naming_the_argument(value):
    with pytest.raises(ValueError, match=r"^dt must be a finite real number") as e:
        check_real("dt", value, 1e-4, 1e-2, unit="s")
    assert len(str(e.value)) < 120 and "\n" not in str(e.value)


def test_the_env_refuses_it_in_one_line():
    with pytest.raises(ValueError, match=r"^dt must be") as e:
        gym.make("ACLDBeam-v1", dt=10**400)
    assert len(str(e.value)) < 120


def test_shown_cuts_long_reprs_and_keeps_short_ones():
    assert shown(3) == "3"
    assert shown("x" * 200).endswith("...") and len(shown("x" * 200)) == 60
