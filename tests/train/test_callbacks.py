"""train.callbacks: the thesis-case evaluation repeats and equals the comparison's row."""

import pytest

from acld_gym.envs.beam_env import ACLDBeamEnv
from baselines.evaluate import metrics_row, rollout
from baselines.policies import SMCPolicy
from train.callbacks import ThesisCaseMonitor


def test_evaluations_repeat_with_the_comparison_seed():
    smc = SMCPolicy()
    mon = ThesisCaseMonitor(ACLDBeamEnv(load_case=1), lqr_ise=1.0)
    ises = []
    for _ in range(2):  # two evaluations, no reseeding by the caller
        obs, _ = mon.reset()
        done = False
        while not done:
            obs, _, term, trunc, _ = mon.step(smc.predict(obs)[0])
            done = term or trunc
        ises.append(mon.last_metrics["ise"])
    assert ises[0] == ises[1]
    ref = metrics_row(1, "smc", rollout(smc, ACLDBeamEnv(load_case=1), seed=0)).ise
    assert ises[0] == pytest.approx(ref, rel=1e-12)
