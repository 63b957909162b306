"""The env's step as algebra: one period of plant and observer as one matrix, the fused output
matrix of the whole step, the load schedule, the reward and the end of an episode, and the
info schema. Written once here; :mod:`acld_gym.envs.batch` runs it for N envs, and the
compiled step (``acld_gym.envs._stepcore``) mirrors the reward and the termination."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from acld_gym.design.discrete import SampledSystem
from acld_gym.design.observer import DiscreteObserver
from acld_gym.physics.loads import TipLoad

if TYPE_CHECKING:
    from acld_gym.design.nominal import NominalDesign

__all__ = [
    "StepLayout",
    "Y_SCALE",
    "OBS_HIST",
    "INFO_KEYS",
    "TERMINATED_BY",
    "observation_size",
    "commands_in_flight",
    "observed_commands",
    "appended_size",
    "estimate_slots",
    "estimate_map",
    "output_matrix",
    "rest_output",
    "load_schedule",
    "reward_terms",
    "reward_of",
    "termination_codes",
]


#: Deflection scale of the observations [m].
Y_SCALE = 1e-3

#: Measurements in the ``"measurement"`` observation.
OBS_HIST = 8

#: The info of every step, single and vector env alike (the vector env's values are arrays
#: with ``_key`` masks): the true tip deflection [m] at the end of the step, the voltage
#: applied [V] and the one requested (the action) [V], whether it was clipped, the tip load
#: [N] and the time [s] at the end of the step, the true reduced state, why the episode
#: ended (:data:`TERMINATED_BY`) and the reward's two terms (their sum is the reward, as
#: Gymnasium's MuJoCo envs report ``reward_*`` terms).
INFO_KEYS = (
    "tip_deflection",
    "voltage",
    "requested_voltage",
    "clipped",
    "tip_load",
    "time",
    "xr_true",
    "terminated_by",
    "reward_deflection",
    "reward_voltage",
)

#: ``info["terminated_by"]`` by termination code (0: the episode goes on).
TERMINATED_BY = (None, "deflection_limit", "non_finite_state")


@dataclass(frozen=True)
class StepLayout:
    """Which slot of the step's vectors holds what: the one owner of the layout, read by
    the batched step (:mod:`acld_gym.envs.batch`) and the compiled step (as integers,
    :meth:`core_kwargs`).

    Input ``z = [x, a, xhat, y_meas, u, f0 (s), f1 (s), w', (s_amp)]``: the beam's state
    (n), the actuator's state ``a`` (below), the observer's state (k), the last
    measurement, the command u (the clipped action), the period's load samples at the s
    sub-steps' starts and ends, the new measurement's noise and, with a slew limit, the
    amplifier's output this period (one row of the batch's Z per env). Output
    ``G z = [x', a', xhat', y_meas', y', x_r', e', y_meas' / Y_SCALE]``: the next state
    (its first :attr:`state` entries replace z's), the true tip deflection, the true
    reduced state (r), and the ``"estimate"`` observation (r + 1).

    The actuator's state (empty without actuator options, so that the layout is v1's):
    the patch voltage V_p (with ``amplifier_bandwidth``; the amplifier's lag makes it a
    state of the plant, right after x), the ``delay`` last commands (the oldest first: it
    drives this period) and the voltage held over the last period (the amplifier's
    output, which a slew limit moves from).
    """

    n: int
    k: int
    r: int
    substeps: int
    delay: int = 0
    lag: bool = False
    slew: bool = False

    @classmethod
    def of(cls, config, nom: NominalDesign, obs: DiscreteObserver) -> StepLayout:
        """The layout of a configuration (:class:`acld_gym.envs.config.EnvConfig`): the
        plant's and the observer's sizes, and the actuator options."""
        return cls(
            n=nom.plant.Ad.shape[0],
            k=obs.n,
            r=nom.design.reduced.order,
            substeps=nom.plant.substeps,
            delay=config.actuator_delay,
            lag=config.amplifier_bandwidth is not None,
            slew=config.slew_rate is not None,
        )

    @property
    def actuated(self) -> bool:
        """Whether the actuator has a state (any of delay, lag, slew)."""
        return self.delay > 0 or self.lag or self.slew

    # --- input z -------------------------------------------------------------------
    @property
    def x(self) -> slice:
        """The beam's state [q; dq/dt]."""
        return slice(0, self.n)

    @property
    def plant(self) -> slice:
        """The sampled plant's state: x, and V_p with the amplifier's lag."""
        return slice(0, self.n + int(self.lag))

    @property
    def patch(self) -> int | None:
        """The patch voltage V_p (with the amplifier's lag)."""
        return self.n if self.lag else None

    @property
    def buffer(self) -> slice:
        """The delayed commands, oldest first."""
        start = self.n + int(self.lag)
        return slice(start, start + self.delay)

    @property
    def held(self) -> int | None:
        """The amplifier's output over the last period (any actuator option)."""
        return self.buffer.stop if self.actuated else None

    @property
    def xhat(self) -> slice:
        start = self.buffer.stop + int(self.actuated)
        return slice(start, start + self.k)

    @property
    def state(self) -> slice:
        """x, a, xhat and y_meas: what one step advances."""
        return slice(0, self.xhat.stop + 1)

    @property
    def y_meas(self) -> int:
        return self.xhat.stop

    @property
    def voltage(self) -> int:
        """The command u, the step's clipped action [V]."""
        return self.xhat.stop + 1

    @property
    def loads(self) -> slice:
        return slice(self.voltage + 1, self.voltage + 1 + 2 * self.substeps)

    @property
    def noise(self) -> int:
        return self.loads.stop

    @property
    def inputs(self) -> slice:
        """The per-step inputs ``[f0, f1, w']``."""
        return slice(self.loads.start, self.noise + 1)

    @property
    def amplifier(self) -> int | None:
        """The amplifier's output this period, computed before the product (slew limit)."""
        return self.noise + 1 if self.slew else None

    @property
    def command(self) -> int:
        """Where the command reaching the amplifier this period is: the oldest delayed one,
        or u."""
        return self.buffer.start if self.delay else self.voltage

    @property
    def drive(self) -> int:
        """The voltage that drives the plant (or the amplifier's lag) this period."""
        return self.amplifier if self.slew else self.command

    @property
    def z_size(self) -> int:
        return self.noise + 1 + int(self.slew)

    # --- output G z ----------------------------------------------------------------
    @property
    def out_y(self) -> int:
        return self.state.stop

    @property
    def out_xr(self) -> slice:
        return slice(self.out_y + 1, self.out_y + 1 + self.r)

    @property
    def out_estimate(self) -> slice:
        """The ``"estimate"`` observation: the scaled x_r estimate and the tip."""
        return slice(self.out_xr.stop, self.out_xr.stop + self.r + 1)

    @property
    def out_size(self) -> int:
        return self.out_estimate.stop

    @property
    def out_voltage(self) -> int | None:
        """The patch voltage at the end of the step in G z (None: it is u)."""
        return self.patch if self.lag else self.held

    def core_kwargs(self) -> dict[str, int]:
        """The layout as the compiled step takes it (``acld_gym.envs._stepcore``)."""
        none = -1
        return {
            "n_state": self.state.stop,
            "i_voltage": self.voltage,
            "i_loads": self.loads.start,
            "i_noise": self.noise,
            "o_ymeas": self.y_meas,
            "o_y": self.out_y,
            "o_xr": self.out_xr.start,
            "o_obs": self.out_estimate.start,
            "n_x": self.n,
            "n_xr": self.r,
            "o_volt": none if self.out_voltage is None else self.out_voltage,
            "i_cmd": self.command,
            "i_held": none if self.held is None else self.held,
            "i_amp": none if self.amplifier is None else self.amplifier,
        }


def observation_size(nom: NominalDesign, obs_mode: str, hist: int = OBS_HIST) -> int:
    return {
        "estimate": nom.design.reduced.order + 1,
        "measurement": hist + 1,
        "full": nom.plant.Ad.shape[0],
    }[obs_mode]


def commands_in_flight(obs_mode: str, delay: int) -> int:
    """How many commands ``observe_commands`` appends to the observation: the ``delay``
    commands still in flight after a step (the delay line, the oldest first: the oldest
    drives the next period), less the newest in the ``"measurement"`` observation, which
    already ends with it. None without a delay (nothing is in flight)."""
    return max(int(delay) - int(obs_mode == "measurement"), 0)


def observed_commands(config) -> int:
    """How many commands the observation of ``config`` (an
    :class:`acld_gym.envs.config.EnvConfig`) appends: :func:`commands_in_flight` with
    ``observe_commands``, else none."""
    if not config.observe_commands:
        return 0
    return commands_in_flight(config.obs_mode, config.actuator_delay)


def appended_size(config) -> int:
    """The entries appended to the design's observation (:func:`observation_size`) by the
    options of ``config`` (:class:`acld_gym.envs.config.EnvConfig`), in this order: the
    commands in flight (``observe_commands``, :func:`commands_in_flight`), then log c
    (``observe_reward_scale``), always last."""
    return observed_commands(config) + int(config.observe_reward_scale)


def estimate_slots(order: int, modes: int) -> np.ndarray:
    """Slots of the ``"estimate"`` observation (``order`` scaled reduced-state entries, one
    (cosine, sine)-like pair per mode in mode order, then the tip) that hold the first
    ``modes`` modes' pairs and the tip: ``[0, ..., 2 modes - 1, order]``."""
    if order % 2 or not 1 <= modes <= order // 2:
        raise ValueError(
            f"modes must be in [1, {order // 2}] (the design model's modes), got {modes!r}"
        )
    return np.r_[np.arange(2 * modes), order]


def estimate_map(obs: DiscreteObserver, xr_scale: np.ndarray) -> np.ndarray:
    """Matrix M with ``[xhat, y] @ M`` = the scaled x_r estimate after the measurement
    update, ``T (xhat + L_c (y - C xhat)) / xr_scale``."""
    lc = obs.Lc[:, 0]
    M = np.vstack([(obs.T @ (np.eye(obs.n) - np.outer(lc, obs.C[0]))).T, (obs.T @ lc)[None, :]])
    return M / xr_scale


def output_matrix(
    plant: SampledSystem,
    nom_plant: SampledSystem,
    obs: DiscreteObserver,
    layout: StepLayout,
    output: np.ndarray,
    SL: np.ndarray,
    est: np.ndarray,
) -> np.ndarray:
    """The whole step as one matrix G, ``G z`` in the slots of ``layout``
    (:class:`StepLayout`):

    * the plant (possibly randomized; with the amplifier's lag its state includes V_p):
      ``x_p' = A_d x_p + B_d V_d + W_0 f_0 + W_1 f_1``, V_d the voltage that drives it;
    * the actuator: the delay line moves by one (the new command u enters at its end),
      the held voltage becomes V_d;
    * the observer on the nominal design, driven by u:
      ``xhat' = (A - L_p C) xhat + L_p y_meas + B u`` (plus the nominal load weights if it
      is fed the load);
    * ``y' = output @ x'`` the true tip deflection, ``y_meas' = y' + w'``,
      ``x_r' = S_L^T x'`` the true reduced state and ``e' = [xhat', y_meas'] M`` the scaled
      estimate (:func:`estimate_map` M).
    """
    lay = layout
    G = np.zeros((lay.out_size, lay.z_size))
    P = lay.plant
    G[P, P] = plant.Ad
    G[P, lay.drive] = plant.Bd[:, 0]
    G[P, lay.loads] = np.hstack([plant.W0, plant.W1])
    buf = lay.buffer
    for j in range(buf.start, buf.stop - 1):
        G[j, j + 1] = 1.0
    if lay.delay:
        G[buf.stop - 1, lay.voltage] = 1.0
    if lay.held is not None:
        G[lay.held, lay.drive] = 1.0
    xh, k = lay.xhat, obs.n
    lp = obs.Lp[:, 0]
    G[xh, xh] = obs.A - np.outer(lp, obs.C[0])
    G[xh, lay.y_meas] = lp
    G[xh, lay.voltage] = obs.B[:, 0]
    if obs.fed_load:
        G[xh, lay.loads] = np.hstack([nom_plant.W0, nom_plant.W1])
    X = G[lay.x]
    y = output @ X
    y_meas = y.copy()
    y_meas[lay.noise] = 1.0
    G[lay.y_meas] = y_meas
    G[lay.out_y] = y
    G[lay.out_xr] = SL.T @ X
    G[lay.out_estimate.start : lay.out_estimate.stop - 1] = est[:k].T @ G[xh] + np.outer(
        est[k], y_meas
    )
    G[lay.out_estimate.stop - 1] = y_meas / Y_SCALE
    return G


def load_schedule(
    plant: SampledSystem, load: TipLoad, start: int, stop: int
) -> tuple[np.ndarray, np.ndarray]:
    """Load samples of periods ``start .. stop-1``: ``(F, tip)`` with F (steps, 2 substeps)
    ``[f0, f1]`` as :meth:`SampledSystem.load_samples` and tip (steps + 1,) the load at
    the period starts ``k dt`` (for ``info``)."""
    k = np.arange(start, stop + 1)
    tt = (k[:-1] * plant.dt)[:, None] + plant.times
    eps = 1e-9 * plant.dt
    F = np.hstack([load(tt[:, :-1] + eps), load(tt[:, 1:] - eps)])
    return F, load(k * plant.dt)


def reward_terms(y, v, y_ref: float, lam: float, v_max: float):
    """The reward and its terms, ``(r, r_y, r_v)`` with ``r_y = -(y / y_ref)^2`` and
    ``r_v = -lam (V / v_max)^2``, ``r = r_y + r_v`` (scalars or arrays; the compiled step
    computes the same in the same order)."""
    r_y = -((y / y_ref) ** 2)
    r_v = -(lam * (v / v_max) ** 2)
    return r_y + r_v, r_y, r_v


def reward_of(y, v, y_ref: float, lam: float, v_max: float):
    """``-(y / y_ref)^2 - lam (V / v_max)^2`` (scalars or arrays; :func:`reward_terms`)."""
    return reward_terms(y, v, y_ref, lam, v_max)[0]


def termination_codes(
    y: np.ndarray, reward: np.ndarray, out: np.ndarray, limit: float
) -> np.ndarray:
    """Why each step ends the episode, as a code into :data:`TERMINATED_BY`: 2
    (``"non_finite_state"``) if the env's output row ``out`` (the new state and everything
    derived from it) or the reward is not finite -- never passed off as a normal step --,
    1 (``"deflection_limit"``) if |y| > ``limit``, else 0."""
    finite = np.isfinite(reward) & np.isfinite(out).all(axis=-1)
    return np.where(~finite, 2, np.where(np.abs(y) <= limit, 0, 1)).astype(np.int8)


def rest_output(layout: StepLayout, est: np.ndarray, w: float) -> np.ndarray:
    """The output row of a beam and observer at rest whose first measurement is ``w`` (the
    sensor noise): the measurement slot and the ``"estimate"`` observation of a zero
    observer state, ``[0, w] M`` (:func:`estimate_map` M) and ``w / Y_SCALE``."""
    out = np.zeros(layout.out_size)
    out[layout.y_meas] = w
    out[layout.out_estimate] = w * np.append(est[-1], 1.0 / Y_SCALE)
    return out
