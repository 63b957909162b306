"""train.scoring.score: any policy scored in one call, the same as the package scores its own
(baselines.analysis.score, the ISE / thesis LQR of train.compare), and one line naming the
argument for each bad input."""

import functools
import json

import gymnasium as gym
import numpy as np
import pytest
import torch

import baselines.evaluation.seeds as bench
from acld_gym.wrappers import ObserveModes, UnitAction
from baselines.evaluation.score import score_policy
from baselines.policies import LQRPolicy
from train.agent import TrainedAgent, export_sb3
from train.scoring import score

N = 3  # test-set episodes of the fast tests (and held-out random loads)
V1 = "ACLDBeam-v1"


@pytest.fixture(scope="module")
def ppo():
    """An SB3 PPO trained 256 steps through UnitAction and VecNormalize, and its VecNormalize."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    torch.set_num_threads(1)
    venv = VecNormalize(
        DummyVecEnv(
            [lambda: UnitAction(gym.make(V1, load_case="random", reward_scale="passive"))] * 2
        )
    )
    model = PPO("MlpPolicy", venv, n_steps=128, batch_size=64, n_epochs=1, seed=0, device="cpu")
    model.learn(256)
    venv.training = False
    return model, venv


@pytest.fixture(scope="module")
def agent():
    return TrainedAgent.load("train/agents/ppo")


def test_sb3_model_scores_as_its_exported_law(ppo):
    model, venv = ppo
    got = score(model, V1, wrappers=[UnitAction], vec_normalize=venv, episodes=N)
    exported = TrainedAgent(export_sb3(model, venv), {})  # volts on the raw observation
    want = score(exported, V1, episodes=N)
    assert got.n_episodes == N and got.test_set == "ACLDBeam-v1/test-v1" and got.version == 2
    np.testing.assert_allclose(got.score.ise, want.score.ise, rtol=1e-6)
    assert got.iqm == pytest.approx(want.iqm, rel=1e-6, abs=1e-9)
    for case in (1, 2, 3, "random"):
        assert got.ise_rel_lqr[case] == pytest.approx(want.ise_rel_lqr[case], rel=1e-6)
    # the model's own VecNormalize is the default; without normalization it is another law
    own = score(model, V1, wrappers=[UnitAction], episodes=1)
    assert own.score.ise[0] == got.score.ise[0]
    raw = score(model, V1, wrappers=[UnitAction], vec_normalize=_no_norm(venv), episodes=1)
    assert abs(raw.score.ise[0] / got.score.ise[0] - 1) > 1e-4  # 256 steps: small actions


def _no_norm(venv):
    class Identity:
        obs_rms = venv.obs_rms

        def normalize_obs(self, obs):
            return obs

    return Identity()


def test_loaded_sb3_model_needs_its_vec_normalize_named(ppo, tmp_path):
    """A model loaded with PPO.load has no env: without ``vec_normalize`` it is refused in
    one line (issue 69: it scored silently without its statistics); with the saved file it
    scores as the in-memory model with its VecNormalize; ``False`` scores it on the raw
    observation, as the model loaded on a plain DummyVecEnv does by default."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv

    model, venv = ppo
    model.save(tmp_path / "model.zip")
    venv.save(str(tmp_path / "vecnormalize.pkl"))
    loaded = PPO.load(tmp_path / "model.zip", device="cpu")
    assert loaded.get_env() is None
    with pytest.raises(ValueError, match=r"^vec_normalize: this PPO model has no env") as info:
        score(loaded, V1, wrappers=[UnitAction], episodes=2)
    msg = str(info.value)
    assert "\n" not in msg and "vecnormalize.pkl" in msg and "vec_normalize=False" in msg
    kept = score(model, V1, wrappers=[UnitAction], vec_normalize=venv, episodes=2)
    got = score(loaded, V1, wrappers=[UnitAction], vec_normalize=tmp_path / "vecnormalize.pkl",
                episodes=2)  # fmt: skip
    np.testing.assert_array_equal(got.score.ise, kept.score.ise)
    assert got.ise_rel_lqr == kept.ise_rel_lqr
    # False: no normalization, as a model whose env is no VecNormalize has with None
    raw = score(loaded, V1, wrappers=[UnitAction], vec_normalize=False, episodes=1)
    plain = DummyVecEnv([lambda: UnitAction(gym.make(V1))])
    with_env = PPO.load(tmp_path / "model.zip", env=plain, device="cpu")
    assert score(with_env, V1, wrappers=[UnitAction], episodes=1).score.ise[0] == raw.score.ise[0]
    assert abs(raw.score.ise[0] / kept.score.ise[0] - 1) > 1e-4  # another law


def test_vec_normalize_false_is_none_for_other_policies():
    passive = lambda obs: np.zeros(1)  # noqa: E731
    a = score(passive, V1, vec_normalize=False, episodes=1)
    b = score(passive, V1, episodes=1)
    assert a.score.ise[0] == b.score.ise[0] and a.iqm == 0.0


#: Against the committed train/agents/compare.json, written on one machine: another CPU's
#: BLAS kernels move an ISE ratio by ~4e-9 (OPENBLAS_CORETYPE=Nehalem or Sandybridge, by hand).
COMMITTED_RTOL = 1e-6


def test_trained_agent_prefix_equals_baselines_score(agent):
    got = score(agent, V1, episodes=N)
    want = score_policy(agent, V1, n_episodes=N)
    assert got.iqm == want.iqm and got.ci == (want.ci_low, want.ci_high)
    np.testing.assert_array_equal(got.score.ise, want.ise)
    rows = json.loads(open("train/agents/compare.json").read())
    rel = {r["case"]: r["ise_rel_lqr"] for r in rows if r["policy"] == "ppo"}
    for case in (1, 2, 3):  # seed 0, as train.compare ran them
        assert got.ise_rel_lqr[case] == pytest.approx(rel[case], rel=COMMITTED_RTOL)


@pytest.mark.slow
def test_trained_agent_full_set_is_compare_json(agent):
    got = score(agent, V1)
    rows = json.loads(open("train/agents/compare.json").read())
    ppo = {r["case"]: r for r in rows if r["policy"] == "ppo"}
    want = ppo[1]["score"]
    assert got.n_episodes == want["n_episodes"] == len(bench.TEST_SETS[V1].seeds)
    for key in ("iqm", "ci_low", "ci_high", "mean_ise", "ise_rel_thesis_lqr"):
        assert got.score.as_dict()[key] == pytest.approx(want[key], rel=COMMITTED_RTOL), key
    for case in (1, 2, 3, "random"):
        assert got.ise_rel_lqr[case] == pytest.approx(ppo[case]["ise_rel_lqr"], rel=COMMITTED_RTOL)


def test_callable_through_the_wrappers_is_the_exported_actor(ppo):
    """The exported actor ([-1, 1] out) as a plain callable through UnitAction, with the
    VecNormalize statistics given separately, scores as the model."""
    model, venv = ppo
    actor = export_sb3(model)  # no normalization inside
    got = score(actor, V1, wrappers=[UnitAction], vec_normalize=venv, episodes=N)
    want = score(model, V1, wrappers=[UnitAction], vec_normalize=venv, episodes=N)
    np.testing.assert_allclose(got.score.ise, want.score.ise, rtol=1e-6)


def test_observe_modes_slots_reach_the_policy():
    """A callable behind ObserveModes sees its 5 slots at every step (and passive, scores 0)."""
    seen = []

    def passive(obs):
        seen.append(np.shape(obs))
        return np.zeros(1)

    wrappers = [UnitAction, functools.partial(ObserveModes, modes=2)]
    got = score(passive, V1, wrappers=wrappers, episodes=1)
    assert set(seen) == {(5,)}
    assert got.iqm == 0.0


def test_passive_scores_zero_and_lqr_is_its_own_yardstick():
    passive = score(lambda obs: np.zeros(1), V1, episodes=N)
    assert passive.iqm == 0.0 and passive.ci == (0.0, 0.0)
    assert all(v > 1 for v in passive.ise_rel_lqr.values())
    lqr = score(LQRPolicy.for_env(gym.make(V1).unwrapped), V1, episodes=N)
    assert lqr.ise_rel_lqr == {1: 1.0, 2: 1.0, 3: 1.0, "random": 1.0}
    np.testing.assert_array_equal(lqr.score.ise, lqr.score.thesis_lqr_ise)


class Counting:
    """A stateful policy (SB3's recurrent protocol): the LQR's action, its state the step
    count of the episode; it records every protocol fault."""

    def __init__(self):
        self.lqr = LQRPolicy.for_env(gym.make(V1).unwrapped)
        self.faults, self.episodes = [], 0

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        start = bool(np.asarray(episode_start).ravel()[0])
        if start:
            self.episodes += 1
            state = 0
        elif state is None:
            self.faults.append("state lost")
            state = 0
        action, _ = self.lqr.predict(obs, deterministic=True)
        return action, state + 1


def test_stateful_policy_gets_its_state_and_episode_start():
    pol = Counting()
    got = score(pol, V1, episodes=2)
    assert pol.faults == []
    assert pol.episodes == 1 + 2 + 3 + 2  # the fit check, the test set, cases 1-3, random
    assert got.ise_rel_lqr == {1: 1.0, 2: 1.0, 3: 1.0, "random": 1.0}


@pytest.mark.parametrize(
    ("kwargs", "error", "name"),
    [
        ({"policy": 42}, TypeError, "policy must be"),
        ({"env_id": "ACLDBeam-v9"}, ValueError, "env_id must be"),
        ({"env_id": "acld_gym:ACLDBeam-v1"}, ValueError, "env_id must be"),
        ({"wrappers": "UnitAction"}, TypeError, "wrappers must be"),
        ({"wrappers": [3]}, TypeError, r"wrappers\[0\] must be"),
        ({"wrappers": [lambda e: 3]}, ValueError, r"wrappers\[0\] \(<lambda>\) must return"),
        ({"episodes": 0}, ValueError, "episodes must be"),
        ({"episodes": 101}, ValueError, "episodes must be"),
        ({"policy": lambda obs: np.zeros(3)}, ValueError, "policy: returned"),
        ({"policy": lambda obs: np.full(1, np.nan)}, ValueError, "policy: returned"),
        ({"vec_normalize": "no/such/vecnormalize.pkl"}, ValueError, "vec_normalize: no file"),
        ({"vec_normalize": object()}, TypeError, "vec_normalize must be"),
        ({"vec_normalize": True}, TypeError, "vec_normalize must be"),
        ({"env_kwargs": {"lam": 1.0}}, ValueError, "env_kwargs: only the observation options"),
        ({"env_kwargs": [("observe_commands", True)]}, TypeError, "env_kwargs: expected a dict"),
    ],
)
def test_bad_input_names_the_argument(kwargs, error, name):
    args = {"policy": lambda obs: np.zeros(1), "env_id": V1, "episodes": 1} | kwargs
    with pytest.raises(error, match=f"^{name}") as info:
        score(**args)
    assert "\n" not in str(info.value)


def test_vector_wrapper_on_the_single_env_names_it():
    from acld_gym.wrappers import vector

    with pytest.raises(ValueError, match=r"^wrappers\[0\] \(UnitAction\) does not fit") as info:
        score(lambda obs: np.zeros(1), V1, wrappers=[vector.UnitAction], episodes=1)
    assert "\n" not in str(info.value)


def test_sb3_model_without_its_wrappers_names_them(ppo):
    model, venv = ppo
    with pytest.raises(ValueError, match=r"^wrappers: the policy acts in \[-1, 1\].*UnitAction"):
        score(model, V1, vec_normalize=venv, episodes=1)
    modes = [UnitAction, functools.partial(ObserveModes, modes=2)]
    with pytest.raises(ValueError, match=r"^(wrappers|vec_normalize): .*\(5,\)"):
        score(model, V1, wrappers=modes, vec_normalize=venv, episodes=1)
    with pytest.raises(ValueError, match=r"^wrappers: the policy observes shape \(9,\)"):
        score(model, V1, wrappers=modes, vec_normalize=_no_norm_none(), episodes=1)


def _no_norm_none():
    class NoObs:
        norm_obs = False

        def normalize_obs(self, obs):
            return obs

    return NoObs()


def test_trained_agent_on_another_level_or_with_wrappers(agent):
    with pytest.raises(ValueError, match=r"^policy: policy 'ppo' was built for another"):
        score(agent, "ACLDBeamLab-v1", episodes=1)
    with pytest.raises(ValueError, match=r"^wrappers: a TrainedAgent acts on the env's raw"):
        score(agent, V1, wrappers=[UnitAction], episodes=1)


def test_seeds_in_one_public_place():
    from train.compare import HELDOUT_SEEDS
    from train.core import evaluate

    assert bench.HELDOUT_SEEDS == evaluate.HELDOUT_SEEDS == HELDOUT_SEEDS
    assert bench.VALIDATION_SEED0 == evaluate.VALIDATION_SEED0
    assert bench.validation_seeds(5) == evaluate.validation_seeds(5)
    held, valid = set(bench.HELDOUT_SEEDS), set(bench.validation_seeds(256))
    test = {s for t in bench.TEST_SETS.values() for s in t.seeds}
    assert not held & valid and not held & test and not valid & test
    assert not (held | valid) & set(bench.RESERVED_SEEDS)


def test_engineer_lqg_keeps_its_filter_state():
    """The engineer's LQG (its Kalman filter and commands in flight are SB3's ``state``)
    scores exactly as baselines.evaluation.score scores it; without its state it is another
    policy."""
    from baselines.engineer import DelayLQGPolicy

    lab = "ACLDBeamLab-v1"
    lqg = DelayLQGPolicy.for_env(gym.make(lab))
    got = score(lqg, lab, episodes=2)
    want = score_policy(lqg, lab, n_episodes=2)
    np.testing.assert_array_equal(got.score.ise, want.ise)
    assert got.iqm == want.iqm and got.ise_rel_lqr["random"] < 1

    class Forgetful:
        observation_fingerprint = lqg.observation_fingerprint

        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            return lqg.predict(obs, None, np.ones(1, dtype=bool), deterministic)[0], None

    lost = score(Forgetful(), lab, episodes=2)
    assert not np.allclose(lost.score.ise, got.score.ise, rtol=1e-3)


def test_gymnasium_wrappers(ppo):
    """Gymnasium's RescaleAction to [-1, 1] is UnitAction's map; a NormalizeObservation is
    frozen while scoring (its statistics do not move)."""
    from gymnasium.wrappers import NormalizeObservation, RescaleAction

    model, venv = ppo
    actor = export_sb3(model, venv)
    unit = score(actor, V1, wrappers=[UnitAction], episodes=1)
    one = np.float32(1)
    rescale = score(actor, V1, wrappers=[lambda e: RescaleAction(e, -one, one)], episodes=1)
    np.testing.assert_allclose(rescale.score.ise, unit.score.ise, rtol=1e-9)
    built = []

    def normalize(env):
        built.append(NormalizeObservation(env))
        built[-1].obs_rms.mean[:] = 1e-9  # "trained" statistics
        return built[-1]

    score(lambda obs: np.zeros(1), V1, wrappers=[normalize], episodes=1)
    assert built and all(not w.update_running_mean for w in built)
    assert all(np.all(w.obs_rms.mean == 1e-9) and w.obs_rms.count == 1e-4 for w in built)
