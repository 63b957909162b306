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
    from acld_gym.envs.presets import preset

    probe = load_probe("guide_ppo_whiten")
    modes = preset(env_id).obs_mode == "estimate"
    T = probe.whitening_transform(env_id, modes, 1, 0.1)
    assert T.shape == (width, width) and np.all(np.isfinite(T))
    u = probe.sample_directions(env_id, modes, 1, 0.1)  # the sample T is made from
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
