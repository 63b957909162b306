"""The compiled step (``acld_gym._stepcore``) against the numpy reference step.

``ACLDBeamEnv.step`` runs in C where it can and falls back to ``ACLDBeamEnv._step``
(numpy) elsewhere; both must give the same episode. The two products sum in
different orders (BLAS vs a column loop), so states agree to rounding, flags exactly.
"""

import copy
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

from acld_gym.envs import beam_env as env_module
from acld_gym.envs.beam_env import COMPILED_STEP, ACLDBeamEnv

needs_core = pytest.mark.skipif(not COMPILED_STEP, reason="ACLD_GYM_PURE_PYTHON=1 was set")


def test_compiled_step_was_built():
    # setup.py builds it (optional, so an install without a compiler still works); here
    # its absence is a failure unless numpy-only stepping was asked for explicitly.
    if os.environ.get("ACLD_GYM_PURE_PYTHON") == "1":
        assert not COMPILED_STEP
    else:
        assert COMPILED_STEP, "acld_gym._stepcore was not built (is a C compiler installed?)"


def _env(compiled: bool, **kw) -> ACLDBeamEnv:
    env = ACLDBeamEnv(**kw)
    env.compiled_step = compiled  # takes effect at the next reset
    return env


def _episode(env, seed, actions, steps_past_end=0):
    obs, info = env.reset(seed=seed)
    rows = [(obs, 0.0, False, False, info)]
    for a in list(actions) + [actions[-1]] * steps_past_end:
        rows.append(env.step(a))
    return rows


def _assert_same(rows_c, rows_p):
    assert len(rows_c) == len(rows_p)
    for (oc, rc, tec, trc, ic), (op, rp, tep, trp, ip) in zip(rows_c, rows_p, strict=True):
        assert oc.dtype == op.dtype == np.float32
        np.testing.assert_allclose(oc, op, rtol=1e-6, atol=1e-6)
        assert rc == pytest.approx(rp, rel=1e-9, abs=1e-12)
        assert (tec, trc) == (tep, trp)
        assert type(tec) is type(tep) is bool and type(trc) is type(trp) is bool
        assert ic.keys() == ip.keys()
        for key in ic:  # rounding relative to the vector's size (xr_true components cancel)
            if key == "terminated_by":
                assert ic[key] == ip[key]
                continue
            scale = np.abs(ip[key]).max()
            np.testing.assert_allclose(ic[key], ip[key], rtol=1e-9, atol=1e-12 * scale + 1e-15,
                                       err_msg=key)


CASES = [
    dict(load_case="random"),
    dict(load_case="random", param_noise=0.1, obs_mode="measurement"),
    dict(load_case=2, obs_mode="full", observer="thesis"),
    dict(load_case=3, deflection_limit=2e-3),  # terminates at the limit, then steps on
    dict(load_case=1, sensor_noise=0.0, lam=0.3, y_ref=5e-4),
]


@needs_core
@pytest.mark.parametrize("kw", CASES, ids=lambda kw: "-".join(f"{k}={v}" for k, v in kw.items()))
def test_compiled_and_numpy_steps_give_the_same_episode(kw):
    acts = np.random.default_rng(1).uniform(-200, 200, (1000, 1)).astype(np.float32)
    rows_c = _episode(_env(True, **kw), 7, acts, steps_past_end=5)
    rows_p = _episode(_env(False, **kw), 7, acts, steps_past_end=5)
    _assert_same(rows_c, rows_p)
    # the run went through the interesting branches
    infos = [r[4] for r in rows_c[1:]]
    assert any(i["clipped"] for i in infos) and not all(i["clipped"] for i in infos)
    assert rows_c[1000][3] and not rows_c[999][3]  # truncated exactly at the last tabulated step
    if "deflection_limit" in kw:
        assert any(r[2] for r in rows_c)


@needs_core
@pytest.mark.parametrize("action", [
    [35.0], (35.0,), np.array([35.0]), np.array([35]), np.array([35.0], np.float32)[::1],
    np.array([35.0], ">f4"), np.array([35.0], np.float16), [np.int8(35)],
], ids=["list", "tuple", "float64", "int", "view", "big-endian", "float16", "int8"])
def test_every_action_type_steps_alike(action):
    # float32/float64 1-element arrays take the compiled path, the rest the numpy path
    ref = _env(True, load_case=2)
    got = _env(True, load_case=2)
    ref.reset(seed=3)
    got.reset(seed=3)
    for _ in range(5):
        o1, r1, *_, i1 = ref.step(np.array([35.0], np.float32))
        o2, r2, *_, i2 = got.step(action)
        np.testing.assert_allclose(o1, o2, rtol=1e-6, atol=1e-7)
        assert r1 == pytest.approx(r2, rel=1e-12) and i1["voltage"] == i2["voltage"] == 35.0


@needs_core
def test_paths_hand_over_state_mid_episode():
    # lists step in numpy, float32 arrays in C: alternating them equals all-C
    acts = np.random.default_rng(2).uniform(-150, 150, (300, 1)).astype(np.float32)
    mixed = [a if k % 3 else [float(a[0])] for k, a in enumerate(acts)]
    _assert_same(_episode(_env(True, load_case="random", obs_mode="measurement"), 4, mixed),
                 _episode(_env(True, load_case="random", obs_mode="measurement"), 4, acts))


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("mode", ["estimate", "measurement", "full"])
def test_pickle_and_deepcopy_continue_identically_in_every_obs_mode(mode, compiled):
    # (the "full" observation of an unpickled env used to be frozen: x was pickled as a
    # copy of the state buffer instead of a view of it)
    env = _env(compiled and COMPILED_STEP, load_case="random", obs_mode=mode)
    env.reset(seed=5)
    for _ in range(10):
        env.step(np.array([30.0], np.float32))
    for duplicate in (lambda e: pickle.loads(pickle.dumps(e)), copy.deepcopy):
        clone = duplicate(env)
        assert type(clone._core) is type(env._core) and clone.k == env.k == 10
        for _ in range(20):
            a = np.array([-40.0], np.float32)
            o1, r1, *_ = env.step(a)
            o2, r2, *_ = clone.step(a)
            np.testing.assert_array_equal(o1, o2)
            assert r1 == r2
        env.reset(seed=5)
        for _ in range(10):
            env.step(np.array([30.0], np.float32))


def test_info_arrays_are_not_overwritten_by_later_steps():
    env = ACLDBeamEnv(load_case=1)
    env.reset(seed=0)
    *_, info = env.step(np.zeros(1, np.float32))
    kept = info["xr_true"].copy()
    env.step(np.array([100.0], np.float32))
    np.testing.assert_array_equal(info["xr_true"], kept)


def test_rendering_steps_in_numpy_and_records_history():
    env = ACLDBeamEnv(load_case=1, render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(3):
        env.step(np.zeros(1, np.float32))
    assert len(env.history) == 3


@needs_core
@pytest.mark.parametrize("change, match", [
    (dict(G=np.zeros((59, 67), np.float32)), "G must be"),
    (dict(z=np.zeros(66)), "inconsistent sizes"),
    (dict(inputs=np.zeros((1000, 20))), "inputs has the wrong shape"),
    (dict(tipf=np.zeros(1000)), "tipf must hold"),
    (dict(obs_mode=3), "obs_mode"),
    (dict(n_obs=8), "obs_mode"),
    (dict(n_x=100), "inconsistent sizes"),
    (dict(o_obs=55), "obs_mode"),
    (dict(i_inputs=10), "inconsistent sizes"),
    (dict(o_xr=58), "inconsistent sizes"),
    (dict(z=np.zeros(134)[::2]), "z must be"),
    (dict(tipf=np.zeros(1001, ">f8")), "tipf must be"),
])
def test_core_constructor_rejects_inconsistent_arrays(change, match):
    from acld_gym.envs._stepcore import StepCore

    env = ACLDBeamEnv(mesh="thesis")  # the sizes below are the thesis mesh's
    env.reset(seed=0)
    args = dict(G=env._G, z=env._z, inputs=env._inputs, tipf=env._tipf, y_hist=env.y_hist,
                **env._layout.core_kwargs(), obs_mode=0, n_obs=7, dt=1e-3, y_ref=1e-3,
                lam=0.01, v_max=120.0, limit=0.02, y_scale=1e-3)
    StepCore(**args)  # the env's own arguments are accepted
    with pytest.raises(ValueError, match=match):
        StepCore(**{**args, **change})


@needs_core
def test_core_declines_what_it_cannot_step_safely():
    from acld_gym.envs._stepcore import StepCore

    a = np.zeros(1, np.float32)
    bare = StepCore.__new__(StepCore)  # never initialized: no arrays
    assert bare.step(a) is None
    with pytest.raises(RuntimeError, match="not initialized"):
        bare.product_seconds(1)
    env = ACLDBeamEnv()
    env.reset(seed=0)
    env._core.k = -1  # out of the tabulated range: the numpy path decides
    assert env._core.step(a) is None


@needs_core
def test_product_timer_checks_its_argument_and_leaves_the_state():
    env = ACLDBeamEnv(load_case=2)
    env.reset(seed=0)
    env.step(np.zeros(1, np.float32))
    z = env._z.copy()
    assert 0 < env._core.product_seconds(100) < 1e-3
    np.testing.assert_array_equal(env._z, z)
    with pytest.raises(ValueError, match="n must be a positive integer"):
        env._core.product_seconds(0)


def test_pure_python_switch_is_read_at_import():
    code = "import acld_gym.envs.beam_env as e; print(e.COMPILED_STEP)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env={**os.environ, "ACLD_GYM_PURE_PYTHON": "1"})
    assert out.stdout.strip() == "False"
    assert env_module.COMPILED_STEP is (env_module.StepCore is not None)


@pytest.mark.parametrize("compiled", [True, False] if COMPILED_STEP else [False])
def test_non_finite_state_terminates_and_says_why(compiled):
    # Issue 14: a NaN must end the episode (abs(nan) > limit is False), with the reason.
    env = _env(compiled, load_case=1)
    env.reset(seed=0)
    env.step(np.zeros(1, np.float32))
    env._z[0] = np.nan  # a plant state gone bad, however it happened
    _, reward, terminated, truncated, info = env.step(np.zeros(1, np.float32))
    assert terminated and not truncated and info["terminated_by"] == "non_finite_state"
    env.reset(seed=0)
    *_, info = env.step(np.zeros(1, np.float32))
    assert info["terminated_by"] is None


@pytest.mark.parametrize("compiled", [True, False] if COMPILED_STEP else [False])
@pytest.mark.parametrize("action", [
    "60", b"60", [True], np.array([True]), np.array([60 + 1j]), np.float32(60.0), 60.0,
    np.array([[60.0]], np.float32), np.array([60.0, 1.0]), [None], np.array([np.nan]),
], ids=["str", "bytes", "bool", "bool-array", "complex", "np-scalar", "float", "2d", "two",
        "none", "nan"])
def test_bad_actions_are_rejected_and_leave_the_state_intact(compiled, action):
    # Issue 14: only real numbers of shape (1,) are an action.
    env = _env(compiled, load_case=2)
    env.reset(seed=3)
    env.step(np.array([10.0], np.float32))
    before = (env._z.copy(), env.k, env.v, env.np_random.bit_generator.state)
    with pytest.raises(ValueError, match="action"):
        env.step(action)
    assert np.array_equal(env._z, before[0]) and (env.k, env.v) == before[1:3]
    assert env.np_random.bit_generator.state == before[3]


def test_layout_owns_every_slot():
    # The fused step's layout (acld_gym.envs.step.StepLayout): its slots tile z and G z
    # exactly, and the env's matrix G has its shape.
    from acld_gym.envs.step import StepLayout

    for mesh in ("thesis", "converged"):
        env = ACLDBeamEnv(mesh=mesh)
        lay = env._layout
        assert isinstance(lay, StepLayout) and env._G.shape == (lay.out_size, lay.z_size)
        z_slots = [lay.x, lay.xhat, slice(lay.y_meas, lay.y_meas + 1),
                   slice(lay.voltage, lay.voltage + 1), lay.loads,
                   slice(lay.noise, lay.noise + 1)]
        assert [s.start for s in z_slots[1:]] == [s.stop for s in z_slots[:-1]]
        assert z_slots[-1].stop == lay.z_size
        assert lay.out_estimate.stop == lay.out_size
        assert lay.out_estimate.stop - lay.out_estimate.start == env.observation_space.shape[0]
