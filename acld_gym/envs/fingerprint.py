"""What an observation means: a fingerprint to store with a policy and check against an env.

An agent trained on ``ACLDBeam-v1`` has learned a function of the observation: the
reduced model's coordinates, the observation scales, the observer and the observation
mode. If any of those differ in the env it is evaluated on, it acts on different
coordinates without any error. :func:`observation_fingerprint` records them (as
JSON-able numbers, so that a trained agent can store them), and
:func:`fingerprint_differences` says what differs. Numbers are compared to a relative
tolerance of :data:`RTOL`: the canonical basis makes them equal to round-off (about
1e-10) on every machine, while a different basis, mesh or observer changes them at
order one.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["observation_fingerprint", "design_fingerprint", "fingerprint_differences", "RTOL"]

#: Relative tolerance of numeric entries (round-off across machines is ~1e-10).
RTOL = 1e-6


def design_fingerprint(nom) -> dict[str, Any]:
    """The nominal design's part (:class:`acld_gym.design.nominal.NominalDesign`): the plant,
    the reduced model's coordinates and the observation scales. Enough for a reference policy, which
    decodes the estimate with them and works with either observer."""
    r = nom.design.reduced
    return {
        "mesh": nom.mesh,
        "basis": nom.basis,
        "dt": float(nom.plant.dt),
        "reduced_A": r.A.tolist(),
        "reduced_B": r.B.ravel().tolist(),
        "reduced_C": r.C.ravel().tolist(),
        "xr_scale": nom.xr_scale.tolist(),
    }


def observation_fingerprint(env) -> dict[str, Any]:
    """Everything the observation of ``env`` (an ``ACLDBeamEnv`` or its vector version,
    wrapped or not) depends on: the env id, the design (:func:`design_fingerprint`), the
    observation mode and the observer (its gains)."""
    e = getattr(env, "unwrapped", env)
    spec = getattr(e, "spec", None)
    obs = e.nom.observer(e.observer_kind)
    return {
        "env_id": getattr(spec, "id", None) or e.env_id,
        **design_fingerprint(e.nom),
        "obs_mode": e.obs_mode,
        "observer": e.observer_kind,
        "observer_Lc": obs.Lc.ravel().tolist(),
        "observer_Lp": obs.Lp.ravel().tolist(),
    }


def fingerprint_differences(expected: dict[str, Any], actual: dict[str, Any]) -> list[str]:
    """Human-readable differences of the keys of ``expected`` (empty when they agree)."""
    out = []
    for key, want in expected.items():
        if key not in actual:
            out.append(f"{key}: recorded {_short(want)}, the env has none")
            continue
        got = actual[key]
        if isinstance(want, (list, float)) and not isinstance(want, bool):
            a, b = np.asarray(want, dtype=float), np.asarray(got, dtype=float)
            if a.shape != b.shape:
                out.append(f"{key}: shape {a.shape} recorded, {b.shape} in the env")
            elif not np.allclose(
                b, a, rtol=RTOL, atol=RTOL * float(np.max(np.abs(a), initial=0.0))
            ):
                rel = float(np.max(np.abs(b - a)) / max(float(np.max(np.abs(a))), 1e-300))
                out.append(f"{key}: differs by {rel:.2g} (relative)")
        elif want != got:
            out.append(f"{key}: recorded {_short(want)}, the env has {_short(got)}")
    return out


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
