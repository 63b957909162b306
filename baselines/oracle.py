r"""Oracles: references told what no deployable policy knows, named for it.

:class:`PlantOracleMPC` (``"mpc_oracle"``) is each level's *causal ceiling* mark: it knows
the episode's true plant and actuator -- the sampled truth plant the env simulates this
episode (:attr:`acld_gym.envs.beam_env.ACLDBeamEnv.episode_plant`: its temperature, its
drawn parameters, the amplifier's lag as a state) and the configuration's delay, slew
limit and sensor noise -- but not the load, past or future: it acts on the tip measurement
of its observation only. It is the MPC of the tip's ISE (a small voltage weight ``rho``)
on that plant, with

* a steady-state Kalman filter on the whole sampled plant (its 36 or 37 states), fed the
  voltage that actually drives it (the command ``actuator_delay`` periods late, through the
  slew limit: the oracle runs the amplifier's delay line and slew itself), the load a white
  disturbance of ``load_std`` newtons through the plant's load input (or, with
  ``load_tau``, a first-order Gauss-Markov state; on 20 test episodes of v1 a correlation
  time of 1-10 ms changed the score by at most 0.003, so the default is white), the sensor
  noise the configuration's;
* the delay by prediction: the state ``actuator_delay`` periods ahead under the commands in
  flight (known exactly), from which the QP plans the commands;
* the slew limit as a rate constraint on the planned commands (where it can bind: a slew
  step below 240 V per period; on the registered levels it cannot, 4180 V per period);
* a QP over ``horizon`` periods with the unconstrained LQR's cost-to-go as terminal weight
  (the discrete Riccati equation on the same plant and cost), solved by OSQP.

It reads the episode's plant at reset through ``start_episode(env)`` (the hook of
:func:`baselines.rollout.rollout`): built for one env, it refuses a batch. On any level it
is a mark, not a policy one could deploy: on ``ACLDBeamHard-v1`` no policy knows the
episode's temperature and parameters. No causal policy that observes the same
measurements and knows no more than it does the load can beat its model; it is not a
proof of optimality (its horizon, its Gaussian load model), so its score is a ceiling
measured, not a bound.

:class:`ClairvoyantReplay` (``"bound_replay"``) replays the clairvoyant bound's commands
(:func:`baselines.rollout.bound_solution`) open loop: the bound's own episode through the
path that scores a policy (tests/baselines/evaluation/test_score.py).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from acld_gym.design.discrete import convolution_matrix, impulse_response
from acld_gym.envs.step import OBS_HIST, Y_SCALE
from acld_gym.physics.actuator import V_LIMIT

from . import arguments
from .policies import MPC_MISSING, mpc_available
from .qp import SETTINGS, solution
from .rollout import bound_solution

__all__ = ["PlantOracleMPC", "ClairvoyantReplay", "tip_measurement", "cost_to_go"]

_Y_UNIT = 1e-3  # the QP's deflection unit [m]


def tip_measurement(obs: np.ndarray, config, order: int) -> float:
    """The last tip measurement [m] in an ``"estimate"`` (its entry ``order``) or
    ``"measurement"`` observation (entry ``OBS_HIST - 1``)."""
    obs = np.asarray(obs, dtype=np.float64)
    if obs.ndim != 1:
        raise ValueError(f"obs: an oracle acts on one env's observation, got shape {obs.shape}")
    if config.obs_mode == "estimate":
        return float(obs[order]) * Y_SCALE
    if config.obs_mode == "measurement":
        return float(obs[OBS_HIST - 1]) * Y_SCALE
    raise ValueError(
        f"obs_mode: an oracle reads the 'estimate' or 'measurement' observation, "
        f"got {config.obs_mode!r}"
    )


def cost_to_go(A: np.ndarray, b: np.ndarray, Q: np.ndarray, rho: float) -> np.ndarray:
    r"""P of the discrete Riccati equation :math:`P = Q + A^T P A - A^T P b (\rho + b^T P
    b)^{-1} b^T P A` by the structured doubling algorithm (quadratic convergence; Chu et
    al. 2004): scipy's Schur method fails on a plant whose amplifier lag has a pole at
    1e-164 (60 kHz sampled at 1 ms)."""
    n = A.shape[0]
    Ak, G, H = A.copy(), np.outer(b, b) / rho, Q.copy()
    eye = np.eye(n)
    for _ in range(60):
        W = np.linalg.solve(eye + G @ H, np.hstack([Ak, G]))
        WA, WG = W[:, :n], W[:, n:]
        H_new = H + Ak.T @ H @ WA
        G = G + Ak @ WG @ Ak.T
        Ak = Ak @ WA
        done = np.linalg.norm(H_new - H) <= 1e-13 * np.linalg.norm(H_new)
        H = 0.5 * (H_new + H_new.T)
        if done:
            return H
    raise RuntimeError("cost_to_go: the doubling algorithm did not converge")


class _EpisodeModel:
    """The episode's sampled plant in balanced coordinates (``x = D z``): A, B (per volt),
    E (where the filter's load noise enters), the tip row c. The beam's raw states mix
    entries of 1e4 with 1e-10; ``D`` balances the beam's block
    (:func:`scipy.linalg.matrix_balance`) and leaves the amplifier's state (a pole at
    1e-164: balancing would scale it by 1e155) as it is. With a load ``memory`` a (per
    period) the load is one more state, :math:`f_{k+1} = a f_k + w_k`, held over each
    period."""

    def __init__(self, plant, output: np.ndarray, memory: float | None = None):
        n, nb = plant.Ad.shape[0], output.size
        c = np.zeros(n)
        c[:nb] = output
        scale = np.ones(n)
        _, (scale[:nb], _) = sla.matrix_balance(plant.Ad[:nb, :nb], permute=False, separate=True)
        A = plant.Ad * (1.0 / scale)[:, None] * scale[None, :]
        B, E, c = plant.Bd[:, 0] / scale, plant.Ed[:, 0] / scale, c * scale
        if memory is not None:
            A = np.block([[A, E[:, None]], [np.zeros((1, n)), np.array([[memory]])]])
            B, E, c = np.append(B, 0.0), np.append(np.zeros(n), 1.0), np.append(c, 0.0)
            n += 1
        self.A, self.B, self.E, self.c, self.n = A, B, E, c, n


class PlantOracleMPC:
    """The plant oracle (module docstring): the ISE's MPC on the episode's own plant and
    actuator, from the tip measurement.

    Parameters
    ----------
    horizon : periods the QP plans over (then the LQR's cost-to-go).
    rho : weight of (V / 120 V)^2 against (y / 1 mm)^2 per period. The defaults scored
        0.003-0.005 above a horizon of 40 with rho 1e-4 on the first 20 test episodes of
        each level; rho between 1e-6 and 1e-2 changed v1's by at most 0.003.
    load_std : the Kalman filter's load, its standard deviation [N].
    load_tau : the load's correlation time [s] (a first-order Gauss-Markov load, a state of
        the filter and of the prediction); None: white across periods.
    """

    name = "mpc_oracle"
    observation_fingerprint = None  # any observation carrying the tip measurement

    def __init__(
        self,
        horizon: int = 80,
        rho: float = 1e-3,
        load_std: float = 1.0,
        load_tau: float | None = None,
    ):
        if not mpc_available():
            raise ImportError(MPC_MISSING)
        self.horizon, self.rho = arguments.horizon(horizon), arguments.positive("rho", rho)
        self.load_std = arguments.positive("load_std", load_std, "N")
        self.load_tau = None if load_tau is None else arguments.positive("load_tau", load_tau, "s")
        self._episode = None

    # --- at reset: the episode's plant ---------------------------------------------------
    def start_episode(self, env) -> None:
        """Build the filter and the QP for ``env``'s current episode (after its reset)."""
        e = env.unwrapped
        c = e.config
        a = None if self.load_tau is None else float(np.exp(-e.dt / self.load_tau))
        m = _EpisodeModel(e.episode_plant, e.nom.output, a)
        sensor = max(float(c.sensor_noise), 1e-9)
        W = np.outer(m.E, m.E) * self.load_std**2 * (1.0 if a is None else 1.0 - a * a)
        X = sla.solve_discrete_are(m.A.T, m.c[:, None], W, np.array([[sensor**2]]))
        self._gain = X @ m.c / (m.c @ X @ m.c + sensor**2)
        self._m = m
        self._qp(m)
        self._config, self._order = c, e.nom.design.reduced.order
        self._delay = int(c.actuator_delay)
        self._slew = c.slew_step if c.slew_step is not None and c.slew_step < 2 * V_LIMIT else None
        self._episode = True
        self._xprior = np.zeros(m.n)  # the beam starts at rest, exactly
        self._inflight = np.zeros(self._delay)  # commands on their way, oldest first
        self._held = 0.0  # the amplifier's last output (the slew limit moves from it)
        self._prob = None

    def _qp(self, m: _EpisodeModel) -> None:
        r"""The condensed QP in u (units of 120 V) from the state z predicted at the first
        period the plan drives: :math:`\min u^T H u + 2 u^T (G z)`."""
        H, n = self.horizon, m.n
        bu = m.B * V_LIMIT
        cy = m.c / _Y_UNIT
        Q = np.outer(cy, cy)
        P = cost_to_go(m.A, bu, Q, self.rho)
        w, U = np.linalg.eigh(P)
        Lp = np.sqrt(np.clip(w, 0.0, None))[:, None] * U.T  # P = Lp^T Lp
        h = impulse_response((m.A, bu[:, None]), cy, H)
        Theta = convolution_matrix(h)  # y_{j+1} from u_0..u_j
        Psi = np.empty((H, n))
        Aj = np.eye(n)
        Gam = np.zeros((n, H))  # x_H from u
        for j in range(H):
            Aj = m.A @ Aj
            Psi[j] = cy @ Aj
            Gam = m.A @ Gam
            Gam[:, j] += bu
        LG, LA = Lp @ Gam, Lp @ Aj
        self._hessian = Theta.T @ Theta + self.rho * np.eye(H) + LG.T @ LG
        self._G = Theta.T @ Psi + LG.T @ LA

    def _solver(self):
        import osqp  # optional dependency: the extra acld-gym[baselines]

        H = self.horizon
        rows = [sp.identity(H, format="csc")]
        if self._slew is not None:
            rows.append(sp.eye(H, H) - sp.eye(H, H, k=-1))
        prob = osqp.OSQP()
        prob.setup(
            P=sp.csc_matrix(np.triu(2.0 * self._hessian)),
            q=np.zeros(H),
            A=sp.vstack(rows, format="csc"),
            l=-np.ones(H * len(rows)),
            u=np.ones(H * len(rows)),
            **SETTINGS,
        )
        return prob

    # --- each step -------------------------------------------------------------------------
    def _drive(self, command: float) -> float:
        """The amplifier's output this period for the command reaching it (the slew limit)."""
        if self._slew is not None:
            command = self._held + float(np.clip(command - self._held, -self._slew, self._slew))
        self._held = command
        return command

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol for one env: ``(action, state)``, the action in volts, shape (1,)."""
        if self._episode is None:
            raise RuntimeError("mpc_oracle: start_episode(env) first (baselines.rollout.rollout)")
        m = self._m
        y = tip_measurement(observation, self._config, self._order)
        x = self._xprior + self._gain * (y - m.c @ self._xprior)
        # the state when the plan starts driving: the commands in flight first
        z, held = x, self._held
        for u in self._inflight:
            if self._slew is not None:
                u = held + float(np.clip(u - held, -self._slew, self._slew))
            held = u
            z = m.A @ z + m.B * u
        if self._prob is None:
            self._prob = self._solver()
        q = 2.0 * (self._G @ z)
        if self._slew is None:
            self._prob.update(q=q)
        else:
            s = self._slew / V_LIMIT
            lo, hi = -np.ones(2 * self.horizon), np.ones(2 * self.horizon)
            lo[self.horizon :], hi[self.horizon :] = -s, s
            lo[self.horizon] += held / V_LIMIT
            hi[self.horizon] += held / V_LIMIT
            self._prob.update(q=q, l=lo, u=hi)
        res = self._prob.solve(raise_error=False)
        command = float(np.clip(V_LIMIT * solution(res, "mpc_oracle")[0], -V_LIMIT, V_LIMIT))
        if self._delay:
            reaching = float(self._inflight[0])
            self._inflight = np.append(self._inflight[1:], command)
        else:
            reaching = command
        self._xprior = m.A @ x + m.B * self._drive(reaching)
        return np.array([command], dtype=np.float32), state


class ClairvoyantReplay:
    """The clairvoyant bound's commands for the env's current episode, replayed open loop
    (``"bound_replay"``; module docstring): they reach the amplifier ``actuator_delay``
    periods later as the bound's voltages."""

    name = "bound_replay"
    observation_fingerprint = None

    def start_episode(self, env) -> None:
        sol, _ = bound_solution(env)
        d = int(env.unwrapped.config.actuator_delay)
        self._commands = np.append(sol.voltage[d:], np.zeros(d)).astype(np.float32)
        self._k = 0

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        v = self._commands[min(self._k, self._commands.size - 1)]
        self._k += 1
        return np.array([v], dtype=np.float32), state
