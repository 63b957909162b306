"""The compiled step (``acld_gym.envs._stepcore.BatchCore``) against the numpy reference step.

Both run the one batched step (:mod:`acld_gym.envs.batch`) on the same arrays; the single
env is its N = 1 case. ``ACLDBeamEnv.step`` runs compiled where it can and falls back to
the numpy step (``BatchStep.advance``) elsewhere; both must give the same episode. The two
products sum in different orders (BLAS or a column loop vs numpy), so states agree to
rounding, flags exactly.
"""

import copy
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

from acld_gym.envs import batch as batch_module
from acld_gym.envs.beam_env import COMPILED_STEP, ACLDBeamEnv
from acld_gym.envs.compiled import NOT_COMPILED
from acld_gym.envs.step import INFO_KEYS

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
        assert list(ic) == list(ip) == list(INFO_KEYS)
        for key in ic:  # rounding relative to the vector's size (xr_true components cancel)
            if key == "terminated_by":
                assert ic[key] == ip[key]
                continue
            assert type(ic[key]) is type(ip[key]), key
            scale = np.abs(ip[key]).max()
            np.testing.assert_allclose(
                ic[key], ip[key], rtol=1e-9, atol=1e-12 * scale + 1e-15, err_msg=key
            )


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
@pytest.mark.parametrize(
    "action",
    [
        [35.0],
        (35.0,),
        np.array([35.0]),
        np.array([35]),
        np.array([35.0], np.float32)[::1],
        np.array([35.0], ">f4"),
        np.array([35.0], np.float16),
        [np.int8(35)],
    ],
    ids=["list", "tuple", "float64", "int", "view", "big-endian", "float16", "int8"],
)
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
    _assert_same(
        _episode(_env(True, load_case="random", obs_mode="measurement"), 4, mixed),
        _episode(_env(True, load_case="random", obs_mode="measurement"), 4, acts),
    )


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
        assert (clone.batch.core is None) == (env.batch.core is None) and clone.k == env.k == 10
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


def test_rendering_records_history():
    env = ACLDBeamEnv(load_case=1, render_mode="rgb_array")
    env.reset(seed=0)
    for v in (0.0, 50.0, -20.0):
        *_, info = env.step(np.array([v], np.float32))
    assert len(env.history) == 3 and env.history[-1] == (
        info["time"],
        info["tip_deflection"],
        -20.0,
    )


def _core_args(env):
    b = env.batch
    return dict(
        GT=b.GT,
        Z=b.Z,
        OUT=b.OUT,
        k=b.k,
        noise=b.noise,
        y_hist=b.y_hist,
        comp=b.codes.comp,
        ncomp=b.codes.ncomp,
        pool=b.codes.pool,
        times=b.times,
        **b.layout.core_kwargs(),
        obs_mode=0,
        n_obs=7,
        dt=1e-3,
        y_ref=1e-3,
        lam=0.01,
        v_max=120.0,
        limit=0.02,
        y_scale=1e-3,
        slew_step=0.0,
        dgemm=None,
    )


@needs_core
@pytest.mark.parametrize(
    "change, match",
    [
        (dict(GT=np.zeros((59, 67), np.float32)), "GT must be"),
        (dict(Z=np.zeros((1, 66))), "GT must be"),
        (dict(noise=np.zeros((2, 1001))), "inconsistent sizes"),
        (dict(k=np.zeros(1, np.int32)), "k must be"),
        (dict(obs_mode=3), "obs_mode"),
        (dict(n_obs=8), "obs_mode"),
        (dict(n_x=100), "inconsistent sizes"),
        (dict(o_obs=55), "obs_mode"),
        (dict(i_loads=10), "inconsistent sizes"),
        (dict(o_xr=58), "inconsistent sizes"),
        (dict(Z=np.zeros((1, 134))[:, ::2]), "Z must be"),
        (dict(noise=np.zeros((1, 1001), ">f8")), "noise must be"),
        (dict(comp=np.zeros((1, 8, 7))), "load arrays"),
        (dict(ncomp=np.array([9])), "not encoded correctly"),
        (dict(dgemm=3), "dgemm must be"),
    ],
)
def test_core_constructor_rejects_inconsistent_arrays(change, match):
    from acld_gym.envs._stepcore import BatchCore

    env = ACLDBeamEnv(mesh="thesis")  # the sizes below are the thesis mesh's
    env.reset(seed=0)
    args = _core_args(env)
    BatchCore(**args)  # the env's own arguments are accepted
    with pytest.raises(ValueError, match=match):
        BatchCore(**{**args, **change})


@needs_core
def test_core_rejects_a_load_encoding_that_would_read_out_of_bounds():
    from acld_gym.envs._stepcore import BatchCore

    env = ACLDBeamEnv(load_case="random")
    env.reset(seed=0)
    args = _core_args(env)
    comp = np.zeros_like(args["comp"])
    comp[0, 0] = (3, 0.0, 1.0, 2e-3, args["pool"].shape[1] - 1, 2, 0, np.nan)  # one too many
    with pytest.raises(ValueError, match="not encoded correctly"):
        BatchCore(**{**args, "comp": comp, "ncomp": np.array([1])})


@needs_core
def test_core_declines_what_it_cannot_step_safely():
    from acld_gym.envs._stepcore import BatchCore

    a = np.zeros(1, np.float32)
    bare = BatchCore.__new__(BatchCore)  # never initialized: no arrays
    assert bare.step_one(a) is None
    with pytest.raises(RuntimeError, match="not initialized"):
        bare.product_seconds(1)
    with pytest.raises(RuntimeError, match="not initialized"):
        bare.step(a)
    env = ACLDBeamEnv()
    env.reset(seed=0)
    env.batch.k[0] = env.max_steps  # past the tabulated range: the numpy path decides
    assert env.batch.core.step_one(a) is None
    assert env.batch.core.step(np.zeros(2)) is None  # not N actions: Python checks them


@needs_core
def test_product_timer_checks_its_argument_and_leaves_the_state():
    env = ACLDBeamEnv(load_case=2)
    env.reset(seed=0)
    env.step(np.zeros(1, np.float32))
    z = env.batch.Z.copy()
    assert 0 < env.batch.core.product_seconds(100) < 1e-3
    np.testing.assert_array_equal(env.batch.Z, z)
    with pytest.raises(ValueError, match="n must be a positive integer"):
        env.batch.core.product_seconds(0)


@needs_core
def test_compiled_info_keys_are_the_schema():
    env = ACLDBeamEnv()
    env.reset(seed=0)
    assert env.batch.core.names() == INFO_KEYS
    assert list(env.step(np.zeros(1, np.float32))[4]) == list(INFO_KEYS)


def test_pure_python_switch_is_read_at_import():
    code = "import acld_gym.envs.beam_env as e; print(e.COMPILED_STEP)"
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "ACLD_GYM_PURE_PYTHON": "1"},
    )
    assert out.stdout.strip() == "False"
    assert batch_module.COMPILED_STEP is (batch_module.BatchCore is not None)
    assert "not built" not in out.stderr  # asked for: no warning


#: A child process in which the compiled step cannot be imported (no C compiler at install).
WITHOUT_COMPILED_STEP = """
import sys, warnings
class Block:
    def find_spec(self, name, path=None, target=None):
        if name == "acld_gym.envs._stepcore":
            raise ImportError(name)
sys.meta_path.insert(0, Block())
warnings.simplefilter("always")
import gymnasium as gym, acld_gym
from acld_gym.envs import batch
gym.make("ACLDBeam-v1").reset(seed=0)
print(batch.COMPILED_STEP)
"""


def test_a_missing_compiled_step_is_said_once():
    """An install without the built extension runs the numpy step and says so in one
    warning at import, not silently (a new user's scores took 3-6x longer)."""
    env = {k: v for k, v in os.environ.items() if k != "ACLD_GYM_PURE_PYTHON"}
    out = subprocess.run(
        [sys.executable, "-c", WITHOUT_COMPILED_STEP],
        capture_output=True,
        text=True,
        check=True,
        env=env,
    )
    assert out.stdout.strip() == "False"
    assert out.stderr.count(NOT_COMPILED) == 1, out.stderr


@pytest.mark.parametrize("compiled", [True, False] if COMPILED_STEP else [False])
def test_non_finite_state_terminates_and_says_why(compiled):
    # Issue 14: a NaN must end the episode (abs(nan) > limit is False), with the reason.
    env = _env(compiled, load_case=1)
    env.reset(seed=0)
    env.step(np.zeros(1, np.float32))
    env.x[0] = np.nan  # a plant state gone bad, however it happened
    _, reward, terminated, truncated, info = env.step(np.zeros(1, np.float32))
    assert terminated and not truncated and info["terminated_by"] == "non_finite_state"
    env.reset(seed=0)
    *_, info = env.step(np.zeros(1, np.float32))
    assert info["terminated_by"] is None


@pytest.mark.parametrize("compiled", [True, False] if COMPILED_STEP else [False])
@pytest.mark.parametrize(
    "action",
    [
        "60",
        b"60",
        [True],
        np.array([True]),
        np.array([60 + 1j]),
        np.float32(60.0),
        60.0,
        np.array([[60.0]], np.float32),
        np.array([60.0, 1.0]),
        [None],
        np.array([np.nan]),
    ],
    ids=[
        "str",
        "bytes",
        "bool",
        "bool-array",
        "complex",
        "np-scalar",
        "float",
        "2d",
        "two",
        "none",
        "nan",
    ],
)
def test_bad_actions_are_rejected_and_leave_the_state_intact(compiled, action):
    # Issue 14: only real numbers of shape (1,) are an action.
    env = _env(compiled, load_case=2)
    env.reset(seed=3)
    env.step(np.array([10.0], np.float32))
    before = (env.batch.Z.copy(), env.k, env.v, env.np_random.bit_generator.state)
    with pytest.raises(ValueError, match="action"):
        env.step(action)
    assert np.array_equal(env.batch.Z, before[0]) and (env.k, env.v) == before[1:3]
    assert env.np_random.bit_generator.state == before[3]


def test_layout_owns_every_slot():
    # The fused step's layout (acld_gym.envs.step.StepLayout): its slots tile z and G z
    # exactly, and the batch's matrix G has its shape.
    from acld_gym.envs.step import StepLayout

    for mesh in ("thesis", "converged"):
        env = ACLDBeamEnv(mesh=mesh)
        lay = env.batch.layout
        assert isinstance(lay, StepLayout) and env.batch.GT.shape == (lay.z_size, lay.out_size)
        z_slots = [
            lay.x,
            lay.xhat,
            slice(lay.y_meas, lay.y_meas + 1),
            slice(lay.voltage, lay.voltage + 1),
            lay.loads,
            slice(lay.noise, lay.noise + 1),
        ]
        assert [s.start for s in z_slots[1:]] == [s.stop for s in z_slots[:-1]]
        assert z_slots[-1].stop == lay.z_size
        assert lay.out_estimate.stop == lay.out_size
        assert lay.out_estimate.stop - lay.out_estimate.start == env.observation_space.shape[0]
