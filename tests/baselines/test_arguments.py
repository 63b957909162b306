"""Every reference's constructor checks its arguments up front (issue 65) with the shared
checks of baselines.arguments: one ValueError naming the argument (and, for a conflict,
both arguments), never a ZeroDivisionError, a LinAlgError, an AttributeError or a message
about another argument."""

from __future__ import annotations

import math

import gymnasium as gym
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import acld_gym  # noqa: F401
from acld_gym.design.nominal import nominal_design
from baselines.engineer import (
    ActuatorMPCPolicy,
    DelayLQGPolicy,
    engineer_policies,
    env_plant,
    rig_model,
)
from baselines.engineer.tuning import search
from baselines.oracle import PlantOracleMPC
from baselines.policies import (
    LQRPolicy,
    MPCPolicy,
    PassivePolicy,
    RewardMPCPolicy,
    SMCPolicy,
    mpc_available,
)

NOM = nominal_design()
THESIS = nominal_design(mesh="thesis")
ENV = gym.make("ACLDBeam-v1").unwrapped


def _cases():
    e = ENV
    return {
        # the probe's
        "dt zero": (lambda: LQRPolicy(dt=0.0), "dt must be >= 0.0001"),  # ZeroDivisionError
        "dt negative": (lambda: LQRPolicy(dt=-1e-3), "dt must be >= 0.0001"),  # 'order ...'
        "dt nan": (lambda: SMCPolicy(dt=math.nan), "dt must be a finite"),  # 'singular'
        "nom and mesh": (
            lambda: LQRPolicy(nom=THESIS, mesh="converged"),
            "mesh='converged' conflicts with nom, designed for mesh='thesis'",
        ),
        "nom and dt": (lambda: PassivePolicy(nom=NOM, dt=2e-3), "dt=0.002 conflicts with nom"),
        "not an env": (lambda: engineer_policies(3), "env must be an ACLDBeam env"),
        "foreign id": (lambda: engineer_policies("CartPole-v1"), "env must be one of this"),
        "module id": (lambda: LQRPolicy.for_env("evil:ACLDBeam-v1"), "env must be one of this"),
        # siblings
        "dt large": (lambda: PassivePolicy(dt=1.0), "dt must be <= 0.01"),
        "mesh": (lambda: LQRPolicy(mesh="fine"), "mesh must be one of"),
        "nom type": (lambda: SMCPolicy(nom="thesis"), "nom must be a NominalDesign"),
        "lqr weight": (lambda: LQRPolicy(nom=NOM, weight=-1.0), "weight must be > 0"),
        "smc eps": (lambda: SMCPolicy(nom=NOM, eps=math.inf), "eps must be a finite"),
        "smc eta": (lambda: SMCPolicy(nom=NOM, eta_factor="1"), "eta_factor must be a finite"),
        "mpc horizon": (lambda: MPCPolicy(nom=NOM, horizon=10**6), "horizon must be an integer"),
        "mpc horizon bool": (lambda: MPCPolicy(nom=NOM, horizon=True), "horizon must be an"),
        "mpc rho": (lambda: MPCPolicy(nom=NOM, rho=math.nan), "rho must be a finite"),
        "reward lam": (lambda: RewardMPCPolicy(nom=NOM, lam=-1.0), "lam must be >= 0"),
        "reward y_ref": (lambda: RewardMPCPolicy(nom=NOM, y_ref=0.0), "y_ref must be > 0"),
        "oracle horizon": (lambda: PlantOracleMPC(horizon=2.0), "horizon must be an integer"),
        "oracle tau": (lambda: PlantOracleMPC(load_tau=math.nan), "load_tau must be a finite"),
        "oracle load": (lambda: PlantOracleMPC(load_std=0), "load_std must be > 0"),
        "rig config": (lambda: DelayLQGPolicy(e.nom, {}), "config must be an EnvConfig"),
        "rig nom": (lambda: DelayLQGPolicy(None, e.config), "nom must be a NominalDesign"),
        "rig conflict": (
            lambda: DelayLQGPolicy(THESIS, e.config),
            "config (mesh='converged', dt=0.001) conflicts with nom (mesh='thesis'",
        ),
        "rig load": (lambda: DelayLQGPolicy(e.nom, e.config, load_std=-1), "load_std must be >"),
        "rig model_std": (
            lambda: DelayLQGPolicy(e.nom, e.config, model_std=[1.0, 2.0]),
            "model_std: expected one value or 8",
        ),
        "rig model": (lambda: DelayLQGPolicy(e.nom, e.config, model=3), "model must be a Rig"),
        "lqg weight": (lambda: DelayLQGPolicy(e.nom, e.config, weight=0), "weight must be > 0"),
        "rig mpc terminal": (
            lambda: ActuatorMPCPolicy(e.nom, e.config, terminal=1),
            "terminal must be True or False",
        ),
        "rig mpc horizon": (lambda: ActuatorMPCPolicy(e.nom, e.config, horizon=0), "horizon"),
        "rig_model conflict": (lambda: rig_model(THESIS, e.config), "rig_model: config (mesh="),
        "env_plant id": (lambda: env_plant("ACLDBeam-v1"), "env must be an ACLDBeam env (any"),
        "search episodes": (lambda: search(e, [], n_episodes=0), "n_episodes must be an"),
    }


@pytest.mark.parametrize("case", sorted(_cases()))
def test_a_bad_argument_is_one_value_error_naming_it(case):
    if not mpc_available() and ("mpc" in case or "oracle" in case or "reward" in case):
        pytest.skip("needs osqp")
    build, words = _cases()[case]
    with pytest.raises(ValueError) as e:
        build()
    assert words in str(e.value) and "\n" not in str(e.value)


def test_matching_arguments_and_an_env_id_are_accepted():
    assert LQRPolicy(nom=THESIS, mesh="thesis").nom is THESIS
    assert LQRPolicy(nom=NOM, dt=1e-3, mesh="converged").nom is NOM
    assert PassivePolicy(dt=2e-3).nom.plant.dt == 2e-3
    assert LQRPolicy.for_env("ACLDBeam-v1").observation_fingerprint == (
        LQRPolicy.for_env(ENV).observation_fingerprint
    )
    assert set(engineer_policies("ACLDBeam-v1")) == set(engineer_policies(ENV))


ODD = st.one_of(
    st.none(),
    st.booleans(),
    st.text(max_size=3),
    st.integers(-(10**20), 10**20),
    st.floats(allow_nan=True, allow_infinity=True),
    st.lists(st.floats(), max_size=2),
)


@settings(max_examples=80, deadline=None)
@given(
    which=st.sampled_from(["lqr", "smc_eps", "smc_eta", "oracle_rho", "oracle_tau", "reward"]),
    value=ODD,
)
def test_fuzz_a_scalar_argument_builds_or_is_refused_naming_it(which, value):
    build, name = {
        "lqr": (lambda v: LQRPolicy(nom=NOM, weight=v), "weight"),
        "smc_eps": (lambda v: SMCPolicy(nom=NOM, eps=v), "eps"),
        "smc_eta": (lambda v: SMCPolicy(nom=NOM, eta_factor=v), "eta_factor"),
        "oracle_rho": (lambda v: PlantOracleMPC(rho=v), "rho"),
        "oracle_tau": (lambda v: PlantOracleMPC(load_tau=v), "load_tau"),
        "reward": (lambda v: RewardMPCPolicy(nom=NOM, horizon=5, lam=v), "lam"),
    }[which]
    if not mpc_available() and which.startswith(("oracle", "reward")):
        return
    try:
        build(value)
    except ValueError as exc:
        assert str(exc).startswith(name), exc


def test_an_lqr_weight_beyond_a_solvable_riccati_equation_is_refused_naming_it():
    """Weights from about 5e28 on made scipy's DARE fail (LinAlgError, found by the fuzz
    above); the bound, nine decades above the thesis's 1e11, still designs."""
    from baselines.arguments import MAX_LQR_WEIGHT

    assert LQRPolicy(nom=NOM, weight=MAX_LQR_WEIGHT).K.shape[0] == 1
    with pytest.raises(ValueError, match=r"^weight must be <= 1e\+20"):
        LQRPolicy(nom=NOM, weight=4.9e28)
