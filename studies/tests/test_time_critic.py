"""``studies/probes/time_critic.py``: the training env appends the episode's remaining time
(1 at the start, 0 in the final observation of an episode that ran its steps), and the
critic's value vanishes when no time is left, is invariant to the load's scale as the
recipe's is, and is never read by the actor."""

import numpy as np
import torch

from studies.tests.probe_scripts import load_probe, tiny_model

tc = load_probe("time_critic")


def test_the_remaining_time_is_appended_and_zero_at_the_time_limit():
    from acld_gym.envs.sb3 import SB3VecEnv

    venv = tc.VecRemainingTime(SB3VecEnv(num_envs=2, episode_length=0.05), steps=50)
    obs = venv.reset()
    assert obs.shape == (2, 10) and np.all(obs[:, -1] == 1.0)
    for k in range(1, 51):
        obs, _, dones, infos = venv.step(np.zeros((2, 1), np.float32))
        if k < 50:
            assert not dones.any()
            np.testing.assert_allclose(obs[:, -1], 1 - k / 50, rtol=1e-6)
    assert dones.all() and all(i["terminal_observation"][-1] == 0.0 for i in infos)
    assert np.all(obs[:, -1] == 1.0)  # the next episodes' first observations
    short = tc.VecRemainingTime(SB3VecEnv(num_envs=1, episode_length=0.05), steps=60)
    short.reset()
    try:  # an env whose episodes are not `steps` long is refused at the first one's end
        for _ in range(50):
            short.step(np.zeros((1, 1), np.float32))
        raise AssertionError("a 50-step episode passed as a 60-step one")
    except RuntimeError as exc:
        assert "truncated after 50 steps" in str(exc)


def test_the_critic_vanishes_at_the_end_is_scale_invariant_and_unread_by_the_actor():
    model, width = tiny_model(tc.config(), make_env=tc.make_time_vec_env)
    assert width == 11  # 9 + log c + r
    pol = model.policy
    with torch.no_grad():
        pol.value_net.weight.copy_(torch.randn_like(pol.value_net.weight))
    assert not pol.value_net.bias.requires_grad and float(pol.value_net.bias) == 0.0
    rng = np.random.default_rng(0)
    u = torch.as_tensor(rng.normal(size=(5, 9)), dtype=torch.float32)
    log_c = torch.as_tensor(rng.normal(size=(5, 1)), dtype=torch.float32)
    r = torch.as_tensor(rng.uniform(0.1, 1, size=(5, 1)), dtype=torch.float32)
    with torch.no_grad():
        v = pol.predict_values(torch.cat([u, log_c, r], dim=1))
        assert torch.all(pol.predict_values(torch.cat([u, log_c, 0 * r], dim=1)) == 0)
        k = 7.0  # u -> sqrt(k) u with c -> k c leaves u / sqrt(c) and the value unchanged
        scaled = pol.predict_values(torch.cat([u * np.sqrt(k), log_c + np.log(k), r], dim=1))
        a1 = pol._predict(torch.cat([u, log_c, r], dim=1), deterministic=True)
        a2 = pol._predict(torch.cat([u, log_c + 3, 1 - r], dim=1), deterministic=True)
    assert torch.allclose(v, scaled, rtol=1e-4, atol=1e-5) and not torch.allclose(v, 0 * v)
    assert torch.equal(a1, a2)
