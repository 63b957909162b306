"""Callbacks: evaluation on the thesis's three load cases (SB3's ``EvalCallback``
with the best model and its ``VecNormalize`` statistics kept), physics metrics
of training and evaluation episodes, and a learning-curve CSV."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import gymnasium as gym
import numpy as np
from stable_baselines3.common.callbacks import BaseCallback, EvalCallback
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.physics.loads import THESIS_CASES
from acld_gym.util.atomic import write_text

from .vec import VecAgentEnv

__all__ = ["THESIS_CASES", "CURVE_FILE", "EpisodeMetrics", "ThesisCaseMonitor", "SaveVecNormalize",
           "PhysicsRolloutLogger", "EvalPhysicsLogger", "thesis_eval_env", "lqr_reference_ise",
           "make_eval_callback"]

#: File name of a run's learning curve (the evaluations on the thesis cases).
CURVE_FILE = "learning_curve.csv"
CURVE_FIELDS = ("timesteps", "case", "ise", "ise_rel_lqr", "peak_mm", "tip_rms_mm",
                "max_voltage_V")


class EpisodeMetrics:
    """Running physics metrics of one episode: ISE [m^2 s], peak and RMS tip
    deflection [mm], max |V| [V] (from ``info``'s ``tip_deflection`` and ``voltage``)."""

    def __init__(self, dt: float = 1e-3):
        self.dt = dt
        self.clear()

    def clear(self) -> None:
        self.n, self.sum_y2, self.peak, self.vmax = 0, 0.0, 0.0, 0.0

    def add(self, y: float, v: float) -> None:
        self.n += 1
        self.sum_y2 += y * y
        self.peak = max(self.peak, abs(y))
        self.vmax = max(self.vmax, abs(v))

    def summary(self) -> dict[str, float]:
        n = max(self.n, 1)
        return {"ise": self.sum_y2 * self.dt, "tip_rms_mm": 1e3 * np.sqrt(self.sum_y2 / n),
                "peak_mm": 1e3 * self.peak, "max_voltage_V": self.vmax}


class ThesisCaseMonitor(gym.Wrapper):
    """Evaluation wrapper of one thesis case: the reward becomes the step's share of
    ISE relative to LQR's, ``-y^2 dt / ISE_LQR`` (an episode's return is
    ``-ISE / ISE_LQR``, so the three cases weigh alike when ``EvalCallback`` ranks
    models), and the finished episode's metrics are kept in ``last_metrics``.

    Every episode is reset with the same ``seed`` (the comparison's seed 0), so all
    evaluations see the same sensor noise: checkpoints are ranked on equal terms, the
    ranking repeats, and an evaluation equals the comparison table's row."""

    def __init__(self, env: ACLDBeamEnv, lqr_ise: float, seed: int = 0):
        super().__init__(env)
        self.seed = int(seed)
        self.case = env.unwrapped.load_case
        self.lqr_ise = float(lqr_ise)
        self.metrics = EpisodeMetrics(env.unwrapped.dt)
        self.last_metrics: dict[str, float] | None = None

    def reset(self, **kwargs):
        self.metrics.clear()
        kwargs["seed"] = self.seed
        return self.env.reset(**kwargs)

    def step(self, action):
        obs, _, terminated, truncated, info = self.env.step(action)
        y = info["tip_deflection"]
        self.metrics.add(y, info["voltage"])
        if terminated or truncated:
            self.last_metrics = dict(self.metrics.summary(), case=self.case)
            self.last_metrics["ise_rel_lqr"] = self.last_metrics["ise"] / self.lqr_ise
        return obs, -(y * y) * self.metrics.dt / self.lqr_ise, terminated, truncated, info


def lqr_reference_ise(cases=THESIS_CASES, seed: int = 0, mesh: str = "converged") -> dict:
    """ISE [m^2 s] of the discrete LQR baseline on each case (the eval's yardstick; it
    normalizes the evaluation, it is not part of the training signal)."""
    from baselines.evaluate import metrics_row, rollout
    from baselines.policies import LQRPolicy

    lqr = LQRPolicy(mesh=mesh)
    return {c: metrics_row(c, "lqr", rollout(lqr, ACLDBeamEnv(load_case=c, mesh=mesh),
                                             seed=seed)).ise
            for c in cases}


def thesis_eval_env(cfg, lqr_ise: dict | None = None) -> VecNormalize:
    """The three thesis cases as one ``VecEnv`` wrapped like the training env
    (statistics frozen; ``EvalCallback`` copies them from the training env)."""
    lqr_ise = lqr_reference_ise(mesh=cfg.mesh) if lqr_ise is None else lqr_ise

    def make(case):
        return lambda: Monitor(ThesisCaseMonitor(ACLDBeamEnv(load_case=case, mesh=cfg.mesh),
                                                 lqr_ise[case]))

    venv = VecAgentEnv(DummyVecEnv([make(c) for c in THESIS_CASES]), cfg.residual, cfg.gamma,
                       mesh=cfg.mesh)
    vn = VecNormalize(venv, gamma=cfg.gamma, **cfg.normalize)
    vn.training, vn.norm_reward = False, False
    return vn


class SaveVecNormalize(BaseCallback):
    """Saves the training env's ``VecNormalize`` statistics to ``path`` (SB3's
    ``model.save`` does not); as ``callback_on_new_best`` it keeps them next to
    ``best_model.zip``."""

    def __init__(self, path: str | Path):
        super().__init__()
        self.path = Path(path)

    def _on_step(self) -> bool:
        vn = self.model.get_vec_normalize_env()
        if vn is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            vn.save(str(self.path))
        return True


class PhysicsRolloutLogger(BaseCallback):
    """Logs the physics of finished training episodes (``rollout/ise``,
    ``rollout/tip_rms_mm``, ``rollout/peak_mm``, ``rollout/max_voltage_V``), not
    only the (shaped, normalized) reward."""

    def _on_training_start(self) -> None:
        self._acc = [EpisodeMetrics() for _ in range(self.training_env.num_envs)]

    def _on_step(self) -> bool:
        infos, dones = self.locals["infos"], self.locals["dones"]
        for acc, info, done in zip(self._acc, infos, dones, strict=True):
            acc.add(info["tip_deflection"], info["voltage"])
            if done:
                for key, value in acc.summary().items():
                    self.logger.record_mean(f"rollout/{key}", value)
                acc.clear()
        return True


class EvalPhysicsLogger(BaseCallback):
    """``callback_after_eval``: logs each thesis case's metrics of the evaluation just
    run (``eval/case{c}/...``) and rewrites ``csv_path`` (the learning curve) with them,
    atomically: a reader never sees a half-written curve."""

    def __init__(self, csv_path: str | Path):
        super().__init__()
        self.csv_path = Path(csv_path)
        self._rows: list[dict] = []

    def _on_step(self) -> bool:
        eval_env = self.parent.eval_env
        for m in (m for m in eval_env.get_attr("last_metrics") if m is not None):
            for key in CURVE_FIELDS[2:]:
                self.logger.record(f"eval/case{m['case']}/{key}", m[key])
            self._rows.append({"timesteps": self.num_timesteps,
                               **{k: m[k] for k in CURVE_FIELDS[1:]}})
        buf = io.StringIO()
        writer = csv.DictWriter(buf, fieldnames=CURVE_FIELDS, lineterminator="\n")
        writer.writeheader()
        writer.writerows(self._rows)
        write_text(self.csv_path, buf.getvalue())
        return True


class EvalFromStart(EvalCallback):
    """``EvalCallback`` that also evaluates before the first step, so the learning
    curve starts at 0 steps (the initial or distilled actor) and that actor is a
    candidate for the best model."""

    def _on_training_start(self) -> None:
        super()._on_training_start()
        self._on_step()  # n_calls == 0: due


def make_eval_callback(cfg, out: Path, n_envs: int) -> EvalCallback:
    """``EvalCallback`` on the three thesis cases every ``cfg.eval_freq`` env steps,
    ranking models by the mean ISE relative to LQR; the best model goes to
    ``out/best/best_model.zip`` with ``out/best/vecnormalize.pkl``."""
    return EvalFromStart(
        thesis_eval_env(cfg), n_eval_episodes=len(THESIS_CASES),
        eval_freq=max(cfg.eval_freq // n_envs, 1), deterministic=True,
        best_model_save_path=str(out / "best"), log_path=str(out / "eval"),
        callback_on_new_best=SaveVecNormalize(out / "best" / "vecnormalize.pkl"),
        callback_after_eval=EvalPhysicsLogger(out / CURVE_FILE), verbose=0)
