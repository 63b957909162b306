r"""The compliance test: the load-to-tip frequency response of the closed loop against the
passive beam's, and the drop of each mode's peak.

A multisine (:mod:`baselines.analysis.frequency`) drives the tip through the env
(:class:`~baselines.analysis.excitation.PulseSuperposition`, two periods of 12.6 s). Its RMS
is set on a pilot run of :data:`PILOT_STEPS` so that the voltage moves by at most
:data:`HEADROOM` of its room to the limit (the multisine's crest factor takes the rest),
and halved, once, if the full run still touches the limit. The passive beam's response to
the same load comes from the same unit-pulse response. Per band of the passive modes, the
peak reduction is :math:`20 \log_{10}(\max|H_{passive}| / \max|H_{closed}|)` [dB].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .effort import at_limit
from .excitation import PulseSuperposition
from .frequency import Multisine, band_peak, frequency_response, transient_residual

__all__ = ["ComplianceTest", "compliance_test", "PILOT_STEPS", "PILOT_RMS", "HEADROOM"]

#: Length of the pilot run [control periods].
PILOT_STEPS = 4000
#: RMS of the pilot multisine [N].
PILOT_RMS = 1e-3
#: Largest voltage change of the pilot run, as a fraction of the room to the limit.
HEADROOM = 0.3


@dataclass(frozen=True)
class ComplianceTest:
    """The outcome of :func:`compliance_test` (``closed`` is None when it failed)."""

    valid: bool
    reason: str
    omega: np.ndarray
    passive: np.ndarray
    closed: np.ndarray | None
    passive_peaks: list[tuple[float, float]]
    closed_peaks: list[tuple[float, float]] | None
    rms_N: float | None
    max_voltage_V: float | None
    transient_residual: float | None

    @property
    def peak_reduction_db(self) -> list[float] | None:
        if self.closed_peaks is None:
            return None
        return [
            float(20.0 * np.log10(p[0] / c[0]))
            for p, c in zip(self.passive_peaks, self.closed_peaks, strict=True)
        ]

    def as_dict(self) -> dict:
        return {
            "valid": self.valid,
            "reason": self.reason,
            "rms_N": self.rms_N,
            "max_voltage_V": self.max_voltage_V,
            "resolution_rad_s": float(self.omega[1] - self.omega[0]),
            "lines": int(self.omega.size),
            "transient_residual": self.transient_residual,
            "passive_peaks": [
                {"compliance_m_per_N": p, "frequency_rad_s": w} for p, w in self.passive_peaks
            ],
            "closed_loop_peaks": None
            if self.closed_peaks is None
            else [{"compliance_m_per_N": p, "frequency_rad_s": w} for p, w in self.closed_peaks],
        }


def compliance_test(
    policy,
    rig: PulseSuperposition,
    ms: Multisine,
    edges: np.ndarray,
    v_max: float,
    rest_voltage: float | None,
    decay_rates=(),
) -> ComplianceTest:
    """The test of the module docstring. ``rest_voltage`` [V] is the policy's voltage at
    rest (from the modal test; None: it does not come to rest, and the test is not run:
    its own oscillation would be read as the response); ``decay_rates`` [1/s] of its
    closed-loop modes bound the transient left in the period read."""
    n = 2 * ms.n_period
    if rig.n_steps < n:
        raise ValueError(f"rig: needs {n} steps for two periods, has {rig.n_steps}")
    unit = ms.signal(1.0, periods=2)
    w = ms.frequencies
    hp = frequency_response(ms, PILOT_RMS * unit, rig.passive(PILOT_RMS * unit).y)
    bands = list(zip(edges[:-1], edges[1:], strict=True))
    passive_peaks = [band_peak(w, hp, lo, hi) for lo, hi in bands]
    room = v_max - abs(rest_voltage or 0.0)

    def failed(why: str, rms=None, vmax=None) -> ComplianceTest:
        return ComplianceTest(False, why, w, hp, None, passive_peaks, None, rms, vmax, None)

    if rest_voltage is None:
        return failed("the policy does not come to rest without a load (modal test)")
    if room <= 0:
        return failed(f"the policy rests at the {v_max:g} V limit")
    pilot = rig.run(policy, PILOT_RMS * unit[:PILOT_STEPS])
    swing = float(np.max(np.abs(pilot.voltage - rest_voltage)))
    rms = PILOT_RMS * (HEADROOM * room / swing if swing > 0 else 1.0)
    for _ in range(2):
        f = rms * unit
        run = rig.run(policy, f)
        vmax = float(np.max(np.abs(run.voltage)))
        if not at_limit(vmax, v_max):
            break
        rms *= 0.5
    else:
        return failed(
            f"a multisine of {2 * rms:.3g} N RMS already drives the patch to the {v_max:g} V limit",
            2 * rms,
            vmax,
        )
    hc = frequency_response(ms, f, run.y)
    closed_peaks = [band_peak(w, hc, lo, hi) for lo, hi in bands]
    return ComplianceTest(
        True,
        "measured",
        w,
        hp,
        hc,
        passive_peaks,
        closed_peaks,
        rms,
        vmax,
        transient_residual(decay_rates, ms) if len(decay_rates) else None,
    )
