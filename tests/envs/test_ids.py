"""The ids' plain data (acld_gym.envs.ids) and the configuration's limits
(acld_gym.envs.limits): ``import acld_gym`` registers every id from them without loading
the configuration or scipy, and the public modules hand out the same objects."""

import subprocess
import sys

import gymnasium as gym

import acld_gym  # noqa: F401
from acld_gym.envs import config, ids, limits, presets, registration
from acld_gym.envs.config import EnvConfig


def test_import_acld_gym_registers_from_the_plain_data_only():
    code = (
        "import sys, gymnasium as gym, acld_gym\n"
        "mods = [m for m in sys.modules if m.split('.')[0] in "
        "('acld_gym', 'baselines', 'train', 'scipy', 'matplotlib', 'control')]\n"
        "print(sorted(mods))\n"
        "print(sorted(k for k in gym.registry if k.startswith('ACLDBeam')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded, registered = out.stdout.splitlines()
    assert loaded == str(
        ["acld_gym", "acld_gym.envs", "acld_gym.envs.ids", "acld_gym.envs.registration"]
    )
    assert registered == str(sorted(ids.PRESETS))


def test_the_public_modules_hand_out_the_same_objects():
    for name in ("PRESETS", "LAB", "HARD", "ENTRY_POINT", "VECTOR_ENTRY_POINT"):
        assert getattr(presets, name) is getattr(ids, name)
    for name in ("check_env_id", "episode_steps", "kwargs_steps"):
        assert getattr(presets, name) is getattr(ids, name)
    assert presets.register_presets is registration.register_presets
    for name in limits.__all__:
        assert getattr(config, name) is getattr(limits, name)


def test_every_id_is_registered_with_its_plain_data():
    for env_id, fields in ids.PRESETS.items():
        spec = gym.spec(env_id)
        assert spec.kwargs == fields and spec.kwargs is not fields  # a copy
        assert spec.entry_point == ids.ENTRY_POINT
        assert spec.vector_entry_point == ids.VECTOR_ENTRY_POINT
        assert presets.preset(env_id) == EnvConfig(**fields)
