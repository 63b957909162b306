r"""The modal test: a policy's closed-loop modes from a small tip pulse through the env.

1. **At rest.** The policy runs without load (:class:`PulseSuperposition` with f = 0, free of
   sensor noise). A policy that drives the patch to the voltage limit, or does not come
   to rest, has no small-signal modes: the test stops there and says why.
2. **The pulse.** A pulse of ``PILOT`` = 0.01 N over one period, then one scaled so that
   the voltage moves by at most half its room to the limit (:data:`HEADROOM`), then half of
   that: the tip's pulse response per newton is :math:`h = (y_a - y_0) / a`, and
   :math:`\|h_a - h_{a/2}\| / \|h_a\|` says how linear the loop is at that amplitude.
3. **Identification.** ERA on h (:mod:`baselines.analysis.sysid`), the dominant mode in
   each band of the passive beam's modes (:mod:`baselines.analysis.modes`), which are
   identified the same way from the passive response.

The record is 2 s (2000 periods): five decay times of the least damped closed-loop mode of
LQR (mode 2, :math:`\zeta\omega` = 1.8 1/s) and 1.7 of the passive beam's, enough for
ERA, which needs the modes' decay, not their end.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .effort import at_limit
from .excitation import PulseSuperposition, Response
from .modes import Mode, band_edges, poles_and_residues, select_modes, window_energy
from .sysid import Identification, identify, order_check

__all__ = [
    "ModalTest",
    "passive_modes",
    "modal_test",
    "RECORD_STEPS",
    "PILOT",
    "HEADROOM",
    "N_MODES",
]

#: Length of the pulse records [control periods].
RECORD_STEPS = 2000
#: The first pulse [N].
PILOT = 0.01
#: Largest voltage change, as a fraction of the room between the rest voltage and the limit.
HEADROOM = 0.5
#: Modes reported.
N_MODES = 3


@dataclass(frozen=True)
class ModalTest:
    """The outcome of :func:`modal_test`."""

    valid: bool
    reason: str
    modes: list[Mode | None]
    rests: bool = True
    """Whether the policy comes to rest, unloaded, away from the limit (step 1)."""
    pulse_N: float | None = None
    max_voltage_V: float | None = None
    rest_voltage_V: float | None = None
    linearity_error: float | None = None
    identification: Identification | None = None
    check: dict = field(default_factory=dict)
    response: np.ndarray | None = None

    def as_dict(self) -> dict:
        ident = self.identification
        hsv = (
            None
            if ident is None
            else (ident.singular_values[:40] / ident.singular_values[0]).tolist()
        )
        return {
            "valid": self.valid,
            "reason": self.reason,
            "rests": self.rests,
            "pulse_N": self.pulse_N,
            "max_voltage_V": self.max_voltage_V,
            "rest_voltage_V": self.rest_voltage_V,
            "linearity_error": self.linearity_error,
            "order": None if ident is None else ident.order,
            "fit_error": None if ident is None else ident.fit_error,
            "order_check": self.check or None,
            "hankel_singular_values": hsv,
            "samples": None if ident is None else ident.n_samples,
        }


def passive_modes(rig: PulseSuperposition) -> tuple[list[Mode], np.ndarray, Identification]:
    """The passive beam's :data:`N_MODES` most energetic modes (ascending), the bands around
    them and the identification, from the rig's unit-pulse tip response."""
    ident = identify(rig.g_y[1:], rig.dt)
    z, r = poles_and_residues(ident.A, ident.B, ident.C)
    energy = np.where(z.imag > 0, window_energy(z, r, ident.n_samples), -np.inf)
    top = np.argsort(-energy)[:N_MODES]
    if not np.all(np.isfinite(energy[top])):
        raise ValueError(
            f"env: the passive pulse response shows fewer than {N_MODES} oscillatory modes"
        )
    freqs = sorted(Mode.of_pole(z[i], rig.dt).frequency_rad_s for i in top)
    edges = band_edges(freqs, rig.dt)
    return select_modes(z, r, rig.dt, edges, ident.n_samples), edges, ident


def _invalid(reason: str, **kw) -> ModalTest:
    return ModalTest(valid=False, reason=reason, modes=[None] * N_MODES, **kw)


def modal_test(policy, rig: PulseSuperposition, edges: np.ndarray, v_max: float) -> ModalTest:
    """Steps 1-3 of the module docstring for ``policy`` on ``rig``."""
    n = min(rig.n_steps, RECORD_STEPS)
    rest = rig.run(policy, np.zeros(n))
    v0 = rest.voltage
    at_limit_share = float(np.mean(at_limit(v0, v_max)))
    tail = v0[-n // 10 :]
    if at_limit_share > 0:
        return _invalid(
            f"without any load the policy holds the patch at the {v_max:g} V "
            f"limit in {100 * at_limit_share:.0f} % of the steps: no small-signal "
            "modes",
            rests=False,
            rest_voltage_V=float(v0[-1]),
        )
    if np.ptp(tail) > 1e-3 * v_max:
        return _invalid(
            f"without any load the voltage does not come to rest (it still "
            f"swings by {np.ptp(tail):.3g} V at the end of {n * rig.dt:g} s)",
            rests=False,
            rest_voltage_V=float(v0[-1]),
        )
    room = HEADROOM * (v_max - float(np.max(np.abs(v0))))

    def pulse(a: float) -> Response:
        f = np.zeros(n)
        f[0] = a
        return rig.run(policy, f)

    def swing(r: Response) -> float:
        return float(np.max(np.abs(r.voltage - v0)))

    a = PILOT
    r = pulse(a)
    for _ in range(3):  # scale to the headroom (twice more if the loop is not linear)
        dv = swing(r)
        if dv == 0.0 or abs(dv / room - 1.0) < 0.2:
            break
        a *= room / dv
        r = pulse(a)
    vmax = float(np.max(np.abs(r.voltage)))
    h = (r.y - rest.y)[1:] / a
    half = (pulse(0.5 * a).y - rest.y)[1:] / (0.5 * a)
    lin = float(np.linalg.norm(h - half) / np.linalg.norm(h))
    common = {
        "pulse_N": a,
        "max_voltage_V": vmax,
        "rest_voltage_V": float(v0[-1]),
        "linearity_error": lin,
        "response": h,
    }
    if at_limit(vmax, v_max):
        return _invalid(
            f"even a {a:.3g} N pulse drives the patch to the {v_max:g} V limit", **common
        )
    ident = identify(h, rig.dt)
    modes = ident.modes(edges)
    check = order_check(ident, edges)
    if any(m is None for m in modes):
        return ModalTest(
            valid=False,
            reason="no oscillatory mode in a band",
            modes=modes,
            identification=ident,
            check=check,
            **common,
        )
    return ModalTest(
        valid=True, reason="identified", modes=modes, identification=ident, check=check, **common
    )
