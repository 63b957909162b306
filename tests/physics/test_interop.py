"""python-control interop (issue 11): the models as control.StateSpace objects agree with
the package's own computations (DC gain = static deflection; H-infinity norms and the
reduction error; step and frequency responses run)."""

from __future__ import annotations

import control
import numpy as np
import pytest

from acld_gym.design.nominal import nominal_design
from acld_gym.design.reduction import frequency_response, hinf_norm
from acld_gym.physics.model import build_model


def test_beam_model_statespace_dc_gain_is_the_static_deflection():
    m = build_model()
    sys = m.to_statespace()
    assert sys.input_labels == ["V[V]", "f[N]"] and sys.output_labels == ["y[m]"]
    dc = control.dcgain(sys)
    assert dc[0, 1] == pytest.approx(m.static_tip_deflection(1.0), rel=1e-9)


def test_reduced_model_norms_agree_with_our_sweep():
    d = nominal_design().design
    red, full = d.reduced.to_statespace(), d.truth.to_statespace()
    assert red.nstates == d.reduced.order and full.nstates == d.truth.n_states
    A, B, _, C = d.plant
    ours, _ = hinf_norm(d.reduced.A, d.reduced.B, d.reduced.C)
    assert control.norm(red[0, 0], "inf", method="scipy") == pytest.approx(ours, rel=1e-4)
    # the reduction error as python-control computes it, within the Hankel bound
    err = control.norm(full[0, 0] - red[0, 0], "inf", method="scipy")
    assert 0 < err <= d.reduced.error_bound
    w = np.array([50.0, 177.0, 900.0])
    ours = frequency_response(A, B, C, w)
    theirs = full[0, 0](1j * w)
    assert np.allclose(theirs, ours, rtol=1e-8)


def test_step_response_runs_on_the_reduced_model():
    red = nominal_design().design.reduced.to_statespace()
    resp = control.step_response(red[0, 1], T=np.linspace(0, 0.5, 501))
    assert np.isfinite(resp.outputs).all() and abs(resp.outputs[-1]) > 0
