r"""The exact small-signal loop of a linear policy: closed-loop eigenvalues, frequency
response and stability margins of the sampled loop (truth plant, the env's observer, the
policy's gain).

**Is the policy linear about rest?** :func:`small_signal_law` asks the policy through
``predict``: it takes central differences about the zero observation (the env's at rest)
with a step that keeps the voltage within a quarter of its room to the limit (a reference
policy declares its gain instead, ``small_signal_gain``, exact where its QP is solved only
to a tolerance), then checks that ``predict`` follows that law: additivity and homogeneity
in random directions at two amplitudes. A policy passes when every check
agrees to :data:`LINEARITY_RTOL`; it is then the affine law :math:`V = v_0 + g^T o` within
the region where no limit or switching is active (LQR, SMC in its boundary layer, the
unconstrained MPC, a linear actor before its clip). Feature maps such as
:math:`[z/|z|, \log|z|]` fail the checks.

**The loop** (``obs_mode="estimate"``). With the env's sampled plant
:math:`(A_d, b, e, c)` (tip :math:`y = c\,x`, load input e for a load held over a period)
and its observer (:class:`acld_gym.design.observer.DiscreteObserver`: :math:`A_o, b_o,
C_o`, prediction gain :math:`L_p`), the observation is linear in the prior estimate and
the measurement, :math:`o = [\hat x, y] \,O` (the estimate map
:func:`acld_gym.envs.step.estimate_map` and the tip entry :math:`y / Y_{scale}`), so the
voltage is :math:`V = v_0 + h_x^T \hat x + h_y\, c\,x` with :math:`h = O g`, and one
period is

.. math::

    \begin{bmatrix} x \\ \hat x \end{bmatrix}^+ =
    \underbrace{\begin{bmatrix} A_d & 0 \\ L_p c & A_o - L_p C_o \end{bmatrix}}_{A_{ol}}
    \begin{bmatrix} x \\ \hat x \end{bmatrix} +
    \begin{bmatrix} b \\ b_o \end{bmatrix} V + \begin{bmatrix} e \\ e_o \end{bmatrix} f,
    \qquad V_c = \begin{bmatrix} h_y c & h_x^T \end{bmatrix}
    \begin{bmatrix} x \\ \hat x \end{bmatrix}

(:math:`e_o` is zero unless the observer is fed the load). Closing :math:`V = V_c` gives
:math:`A_{cl} = A_{ol} + [b; b_o][h_y c, h_x^T]`.

**The actuator** (``ACLDBeamLab-v1``'s options). With ``amplifier_bandwidth`` the episode's
plant :math:`(A_d, b, e)` already holds the lag (its state gains the patch voltage,
:func:`acld_gym.physics.actuator.with_amplifier`; c reads the tip from the beam's part).
With ``actuator_delay`` = d the command reaches the amplifier d periods late: the loop gains
the d held commands :math:`s_1 = V_{k-1}, \dots, s_d = V_{k-d}` (a shift register, the
plant driven by :math:`s_d`), while the observer is fed the command itself, as in the env.
A slew limit is a nonlinearity; the loop is the env's while it does not bind (a change of
less than ``slew_rate * dt`` per period: always for the lab rig's 4180 V against the
240 V of the whole range).

**Margins** (:func:`margins`): the loop broken at the actuator. The voltage applied to the
patch drives both the beam and the observer (as in the env, whose observer reads the
applied voltage), and the policy's voltage :math:`V_c` comes back:
:math:`L(z) = -[h_y c, h_x^T](zI - A_{ol})^{-1}[b; b_o]`, closed by :math:`V = V_c`
(negative feedback on -L). python-control's ``stability_margins`` reads it from its
frequency response up to the Nyquist frequency, on a grid refined around every lightly
damped pole.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from acld_gym.design.discrete import SampledSystem
from acld_gym.design.observer import DiscreteObserver
from acld_gym.envs.step import Y_SCALE, estimate_map

from .modes import Mode, poles_and_residues, select_modes

__all__ = [
    "LinearLaw",
    "small_signal_law",
    "ObserverLoop",
    "frequency_response",
    "margins",
    "LINEARITY_RTOL",
    "MIN_PROBE",
]

#: Relative tolerance of the linearity checks of :func:`small_signal_law` (an MPC's QP is
#: solved to about 1e-5 V, 1e-4 of the probes' voltage changes).
LINEARITY_RTOL = 1e-3
#: Smallest probe of :func:`small_signal_law` [observation units; a 1 N pulse gives order 1].
MIN_PROBE = 1e-6


@dataclass(frozen=True)
class LinearLaw:
    """An affine voltage law about rest, :math:`V = v_0 + g^T o` [V] (o the observation)."""

    gain: np.ndarray
    offset: float


def _voltages(policy, obs: np.ndarray) -> np.ndarray:
    """``predict`` on a batch of observations, as float64 volts (n,)."""
    v, _ = policy.predict(obs.astype(np.float32), deterministic=True)
    return np.asarray(v, dtype=np.float64).reshape(obs.shape[0])


def _declared_gain(policy, obs_size: int) -> np.ndarray | None:
    """The gain on the observation of a policy that declares its small-signal law, as the
    reference policies do (:meth:`baselines.policies._Policy.small_signal_gain`, V = -K x_r,
    with ``reduced_state`` its linear decoding of the observation); None otherwise."""
    if not (hasattr(policy, "small_signal_gain") and hasattr(policy, "reduced_state")):
        return None
    K = np.asarray(policy.small_signal_gain(), dtype=float)
    return -np.asarray(policy.reduced_state(np.eye(obs_size)), dtype=float) @ K


def small_signal_law(
    policy, obs_size: int, v_max: float, seed: int = 0
) -> tuple[LinearLaw | None, str]:
    """The policy's affine law about the zero observation, or None and why not (module
    docstring). The probes stay within a quarter of the room to the +/-``v_max`` limit and
    are at least :data:`MIN_PROBE` in observation units, so that a law affine only in a
    sliver about zero (a norm floor, a dead zone) is not taken for a linear one."""
    _, state = policy.predict(np.zeros(obs_size, np.float32), deterministic=True)
    if state is not None:
        return None, (
            "the policy has a state (a dynamic law, e.g. its own observer on the "
            "measurements, or a memory of its own commands): no static law of the observation"
        )
    v0 = float(_voltages(policy, np.zeros((1, obs_size)))[0])
    room = v_max - abs(v0)
    if room <= 1e-9 * v_max:
        return None, f"the policy is at the {v_max:g} V limit at rest ({v0:+.4g} V)"
    eye = np.eye(obs_size)
    h = 1e-3
    while np.abs(_voltages(policy, h * eye) - v0).max() > 0.25 * room:
        h *= 0.25
        if h < MIN_PROBE:
            return None, (
                f"the voltage leaves a quarter of the room to the limit for "
                f"observation changes below {MIN_PROBE:g}: no linear region"
            )
    declared = _declared_gain(policy, obs_size)
    if declared is not None:
        gain = declared
    else:
        gain = (_voltages(policy, h * eye) - _voltages(policy, -h * eye)) / (2.0 * h)
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(3, obs_size))
    d *= h / np.linalg.norm(d, axis=1, keepdims=True)
    worst = 0.0
    for scale in (1.0, 0.1):
        probes = scale * np.vstack([d, d[:1] + d[1:2]])
        want = v0 + probes @ gain
        got = _voltages(policy, probes)
        ref = np.maximum(np.abs(want - v0), 1e-3 * max(1.0, abs(v0)))
        worst = max(worst, float(np.max(np.abs(got - want) / ref)))
    if worst > LINEARITY_RTOL:
        return None, (
            f"predict is not affine about rest: the linear prediction misses by "
            f"{100 * worst:.3g} % (tolerance {100 * LINEARITY_RTOL:g} %)"
        )
    return LinearLaw(gain=gain, offset=v0), "affine about rest"


@dataclass(frozen=True, eq=False)
class ObserverLoop:
    """The env's loop around a linear law (module docstring): plant (with the amplifier's lag
    where there is one), tip row of its state, observer, the observation's map
    ``[xhat, y] -> o`` and the actuator's delay [control periods]."""

    plant: SampledSystem
    output: np.ndarray
    observer: DiscreteObserver
    obs_map: np.ndarray
    observer_load: np.ndarray
    delay: int = 0

    @classmethod
    def from_env(cls, env) -> ObserverLoop:
        """The loop of ``env`` (any wrapper) for its current episode's plant; ``ValueError``
        unless it observes the ``"estimate"``."""
        e = env.unwrapped
        if e.obs_mode != "estimate":
            raise ValueError(
                f"env: the exact loop is built for obs_mode='estimate', got {e.obs_mode!r}"
            )
        nom = e.nom
        obs = nom.observer(e.observer_kind)
        M = estimate_map(obs, nom.xr_scale)  # [xhat, y] @ M: the scaled reduced estimate
        tip = np.zeros((obs.n + 1, 1))
        tip[-1, 0] = 1.0 / Y_SCALE
        e_o = nom.plant.Ed[:, 0] if obs.fed_load else np.zeros(obs.n)
        plant = e.episode_plant
        c = np.zeros(plant.Ad.shape[0])  # the lag's state, if any, does not reach the tip
        c[: nom.output.size] = nom.output
        return cls(
            plant=plant,
            output=c,
            observer=obs,
            obs_map=np.hstack([M, tip]),
            observer_load=e_o,
            delay=int(e.config.actuator_delay),
        )

    @property
    def n_states(self) -> int:
        return self.plant.Ad.shape[0] + self.delay + self.observer.n

    def open_loop(self, law: LinearLaw) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A_ol, b_v, c_v, e_f)``: the loop broken at the actuator, with the load input, on
        the state ``[x, s_1..s_d, xhat]``."""
        p, o, c, d = self.plant, self.observer, self.output, self.delay
        n, k = p.Ad.shape[0], o.n
        h = self.obs_map @ np.asarray(law.gain, dtype=float)
        lp = o.Lp[:, 0]
        m = n + d  # the observer's first state
        A = np.zeros((m + k, m + k))
        b = np.zeros(m + k)
        A[:n, :n] = p.Ad
        if d:
            A[:n, m - 1] = p.Bd[:, 0]  # the plant is driven by the command d periods old
            A[n + 1 : m, n : m - 1] = np.eye(d - 1)  # s_{j+1} <- s_j
            b[n] = 1.0  # s_1 <- V
        else:
            b[:n] = p.Bd[:, 0]
        A[m:, :n] = np.outer(lp, c)
        A[m:, m:] = o.A - np.outer(lp, o.C[0])
        b[m:] = o.B[:, 0]  # the observer is fed the command itself
        cv = np.concatenate([h[k] * c, np.zeros(d), h[:k]])
        ef = np.concatenate([p.Ed[:, 0], np.zeros(d), self.observer_load])
        return A, b, cv, ef

    def closed_loop(self, law: LinearLaw) -> np.ndarray:
        """:math:`A_{cl}`, the loop's one-period map."""
        A, b, cv, _ = self.open_loop(law)
        return A + np.outer(b, cv)

    def tip_row(self) -> np.ndarray:
        return np.concatenate([self.output, np.zeros(self.delay + self.observer.n)])

    def modes(self, law: LinearLaw, edges: np.ndarray, n_window: int) -> list[Mode | None]:
        """The closed loop's dominant mode per band, in the tip's response to a load pulse
        (:func:`~baselines.analysis.modes.select_modes`)."""
        _, _, _, ef = self.open_loop(law)
        z, r = poles_and_residues(self.closed_loop(law), ef, self.tip_row())
        return select_modes(z, r, self.plant.dt, edges, n_window)

    def spectral_radius(self, law: LinearLaw) -> float:
        return float(np.max(np.abs(np.linalg.eigvals(self.closed_loop(law)))))

    def compliance(self, law: LinearLaw | None, omega: np.ndarray) -> np.ndarray:
        """Load-to-tip frequency response [m/N] at ``omega`` [rad/s] of the closed loop (the
        passive beam for ``law=None``), for a load held over each period."""
        if law is None:
            p = self.plant
            return frequency_response(p.Ad, p.Ed[:, 0], self.output, omega, p.dt)
        _, _, _, ef = self.open_loop(law)
        return frequency_response(self.closed_loop(law), ef, self.tip_row(), omega, self.plant.dt)


def frequency_response(
    A: np.ndarray, b: np.ndarray, c: np.ndarray, omega: np.ndarray, dt: float
) -> np.ndarray:
    r""":math:`c\,(zI - A)^{-1} b` at :math:`z = e^{i\omega\Delta}` (complex, by solves)."""
    omega = np.asarray(omega, dtype=float)
    n = A.shape[0]
    out = np.empty(omega.size, dtype=complex)
    eye = np.eye(n)
    for i in range(0, omega.size, 512):
        z = np.exp(1j * omega[i : i + 512] * dt)
        M = z[:, None, None] * eye - A
        rhs = np.broadcast_to(b.astype(complex), (z.size, n))[..., None]
        out[i : i + 512] = np.linalg.solve(M, rhs)[..., 0] @ c
    return out


def _margin_grid(A: np.ndarray, dt: float, points: int = 6000) -> np.ndarray:
    """Frequencies up to Nyquist: a log grid plus 33 points across every pole of damping
    ratio below 0.3 (within 8 half-power widths). Poles at z = 0 (a delay's held commands)
    are no resonance and are left out."""
    nyq = np.pi / dt
    grid = [np.geomspace(1.0, nyq * (1 - 1e-9), points)]
    z = np.linalg.eigvals(A).astype(complex)
    s = np.log(z[np.abs(z) > 1e-12]) / dt
    for si in s[s.imag > 0]:
        w, sigma = abs(si.imag), max(-si.real, 1e-3)
        if -si.real < 0.3 * abs(si) and w < nyq:
            grid.append(w + sigma * np.linspace(-8.0, 8.0, 33))
    w = np.concatenate(grid)
    return np.unique(w[(w > 0) & (w < nyq)])


def margins(loop: ObserverLoop, law: LinearLaw) -> dict:
    """Gain and phase margins of the loop broken at the actuator (module docstring), with
    python-control, and the closed loop's stability.

    Returns ``{"gain_margin_db", "gain_margin_rad_s"`` (the phase crossover where it is
    read), ``"gain_reduction_margin_db", "gain_reduction_margin_rad_s"``,
    ``"phase_margin_deg", "phase_margin_rad_s"`` (the gain crossover),
    ``"stability_margin"`` (the smallest :math:`|1 + L|`), ``"stability_margin_rad_s"``,
    ``"closed_loop_spectral_radius"``, ``"closed_loop_stable"}``; a margin without a
    crossover is None.

    * Each crossing of the negative real axis, :math:`L = -1/k`, is a gain k at which the
      loop changes stability: the gain margin is the smallest k > 1 (in dB), the gain
      reduction margin the largest k < 1. python-control finds the crossings between
      frequencies of the grid; the two where :math:`L` is real by symmetry, DC (z = 1)
      and the Nyquist frequency (z = -1), are added here (LQR's nearest one is at DC).
    * The phase margin is the smallest change of phase, lag or lead, that brings a gain
      crossover onto -1 (python-control's value, which it signs negative when lead gets
      there first, taken in magnitude).
    """
    import control  # python-control takes ~2.7 s to import: only the margins need it

    A, b, cv, _ = loop.open_loop(law)
    dt = loop.plant.dt
    w = _margin_grid(A, dt)
    resp = -frequency_response(A, b, cv, w, dt)
    frd = control.frd(resp, w, dt=dt)
    gms, pms, _, wpcs, wgcs, _ = control.stability_margins(frd, returnall=True)
    _, _, sm, _, _, wms = control.stability_margins(frd)
    crossings = [
        (float(g), float(x)) for g, x in zip(np.atleast_1d(gms), np.atleast_1d(wpcs), strict=True)
    ]
    ends = np.array([0.0, np.pi / dt])
    for x, value in zip(ends, -frequency_response(A, b, cv, ends, dt).real, strict=True):
        if value < 0:
            crossings.append((-1.0 / value, float(x)))
    up = [c for c in crossings if np.isfinite(c[0]) and c[0] > 1.0]
    down = [c for c in crossings if np.isfinite(c[0]) and 0.0 < c[0] < 1.0]
    gm_up = min(up) if up else None
    gm_down = max(down) if down else None
    pm = [
        (abs(float(p)), float(x))
        for p, x in zip(np.atleast_1d(pms), np.atleast_1d(wgcs), strict=True)
        if np.isfinite(p)
    ]
    pm_min = min(pm) if pm else None

    def num(x):
        return float(x) if x is not None and np.isfinite(x) else None

    rho = loop.spectral_radius(law)
    return {
        "gain_margin_db": None if gm_up is None else float(20 * np.log10(gm_up[0])),
        "gain_margin_rad_s": None if gm_up is None else gm_up[1],
        "gain_reduction_margin_db": None if gm_down is None else float(20 * np.log10(gm_down[0])),
        "gain_reduction_margin_rad_s": None if gm_down is None else gm_down[1],
        "phase_margin_deg": None if pm_min is None else pm_min[0],
        "phase_margin_rad_s": None if pm_min is None else pm_min[1],
        "stability_margin": num(sm),
        "stability_margin_rad_s": num(wms),
        "closed_loop_spectral_radius": rho,
        "closed_loop_stable": bool(rho < 1.0),
    }
