"""``studies/probes/guide_ppo_whiten.py`` and ``guide_sac_whiten.py``: the fixed ZCA
whitening both put before ``VecNormalize`` (:func:`whitening_transform`)."""

import numpy as np
import pytest

from studies.tests.probe_scripts import load_probe


@pytest.mark.parametrize("env_id, width", [("ACLDBeamHard-v1", 9), ("ACLDBeamLab-v1", 3)])
def test_the_transform_whitens_the_observations_directions(env_id, width):
    """T is a square matrix of the observation's width (``ObserveModes(modes=1)`` where the
    level observes the estimate) that takes the second moment of its own sample's directions
    to one whose largest value is 1 and whose spread is more than 10x narrower than the raw
    one: the 8 collinear measurements of the Hard level become better conditioned."""
    import gymnasium as gym

    from acld_gym.envs.presets import preset
    from acld_gym.wrappers import vector

    probe = load_probe("guide_ppo_whiten")
    modes = preset(env_id).obs_mode == "estimate"
    T = probe.whitening_transform(env_id, modes, 1, 0.1)
    assert T.shape == (width, width) and np.all(np.isfinite(T))
    # the same sample, drawn again as the function draws it
    venv = vector.UnitAction(gym.make_vec(env_id, 64, load_case="random"))
    if modes:
        venv = vector.ObserveModes(venv, modes=1)
    rng = np.random.default_rng(12345)
    obs, _ = venv.reset(seed=12345)
    zs = []
    for _ in range(1000):
        zs.append(obs.copy())
        obs, *_ = venv.step(rng.uniform(-0.1, 0.1, (64, 1)).astype(np.float32))
    z = np.concatenate(zs)
    z = z[np.linalg.norm(z, axis=1) > 0]
    u = z / np.linalg.norm(z, axis=1, keepdims=True)
    second = u.T @ u / len(u)  # the second moment T whitens (ridge 1e-3 of its largest value)
    lam = np.linalg.eigvalsh(T @ second @ T)
    assert np.allclose(T, T.T) and lam.max() == pytest.approx(1.0, abs=2e-3)
    # the ridge bounds the whitened spread (1 / (1 + 1e-3 / value)); the raw spread is wider
    assert np.linalg.cond(second) > 10 * lam.max() / lam.min()


def test_the_sac_probe_imports_the_same_transform():
    """The SAC probe takes the PPO probe's transform by import, not a copy of it."""
    import sys

    sac = load_probe("guide_sac_whiten")
    assert sac.whitening_transform.__module__ == "guide_ppo_whiten"
    assert sac.whitening_transform is sys.modules["guide_ppo_whiten"].whitening_transform
