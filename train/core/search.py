"""``vrs``, the benchmark's recipe: vectorised random search (ARS, Mania et al. 2018,
"V1-t") on the linear direction actor, every perturbed actor side by side in the
native batched env on common episodes. Learns from the env's reward only."""

from __future__ import annotations

import gymnasium as gym
import numpy as np

import acld_gym  # noqa: F401  (registers the env ids)
from acld_gym.wrappers import whitening
from baselines.evaluation.seeds import SEARCH_SEEDS

from ..config import TrainConfig
from ..features import direction_features
from .evaluate import CurveCallback, eval_schedule
from .search_settings import RandomSearch

__all__ = ["LinearDirectionActor", "whitening", "RandomSearch", "train_random_search"]


# --- the linear direction actor -------------------------------------------------
class LinearDirectionActor:
    r"""The switching actor :math:`V = V_{max}\,\mathrm{clip}(w \cdot f + b, -1, 1)` on
    :math:`f = [u/|u|, \log|u|]` of :math:`u = T^T z`, z the raw observation and T a fixed
    whitening matrix estimated from the agent's own observations (identity if None;
    ``theta = [w, b]``). ``features=None`` uses f = u instead (a saturated linear
    state feedback).

    ``predict`` follows SB3's protocol and returns volts, so
    :func:`baselines.evaluate.rollout` runs it like any baseline.
    """

    def __init__(
        self,
        theta: np.ndarray,
        v_max: float = 120.0,
        features: str | None = "direction",
        transform: np.ndarray | None = None,
    ):
        self.theta = np.asarray(theta, dtype=np.float64).copy()
        self.v_max = float(v_max)
        self.features = features
        self.transform = None if transform is None else np.asarray(transform, np.float64)

    @staticmethod
    def actions(
        obs: np.ndarray,
        thetas: np.ndarray,
        features: str | None = "direction",
        transform: np.ndarray | None = None,
    ) -> np.ndarray:
        """Actions in [-1, 1], shape (n,), of one parameter row per observation row."""
        u = np.asarray(obs, np.float64)
        if transform is not None:
            u = u @ transform
        f = direction_features(u) if features == "direction" else u
        return np.clip(np.einsum("ni,ni->n", f, thetas[:, :-1]) + thetas[:, -1], -1.0, 1.0)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: ``(voltages, state)``, shape (n, 1) for a batch or (1,)."""
        obs = np.asarray(observation, dtype=np.float64)
        batched = obs.ndim == 2
        obs2 = np.atleast_2d(obs)
        a = self.actions(
            obs2,
            np.broadcast_to(self.theta, (obs2.shape[0], self.theta.size)),
            self.features,
            self.transform,
        )
        v = (self.v_max * a)[:, None].astype(np.float32)
        return (v if batched else v[0]), state

    def as_dict(self) -> dict:
        return {
            "theta": self.theta.tolist(),
            "v_max": self.v_max,
            "features": self.features,
            "transform": None if self.transform is None else self.transform.tolist(),
        }


class _CandidateEnvs:
    """One native vector env per training load case, with ``per_candidate`` episodes of
    that case for each of ``n_candidates`` parameter rows (candidate-major), with the training
    env options ``env_kwargs``."""

    def __init__(
        self,
        env_id: str,
        loads: dict,
        n_candidates: int,
        features: str | None = "direction",
        env_kwargs: dict | None = None,
    ):
        self.envs = {}
        self.features = features
        self.n_candidates = n_candidates
        for case, n in loads.items():
            n = int(n)
            venv = gym.make_vec(
                env_id, num_envs=n_candidates * n, load_case=case, **(env_kwargs or {})
            ).unwrapped
            self.envs[case] = (venv, n)
        first = next(iter(self.envs.values()))[0]
        self.v_max = float(first.single_action_space.high[0])
        self.horizon = int(first.horizon)
        self.n_obs = int(first.single_observation_space.shape[0])

    @property
    def steps_per_round(self) -> int:
        return sum(v.num_envs for v, _ in self.envs.values()) * self.horizon

    def returns(
        self,
        thetas: np.ndarray,
        seed: int,
        common: bool = True,
        transform: np.ndarray | None = None,
        collect: list | None = None,
    ) -> np.ndarray:
        """Returns, shape (n_candidates, episodes). ``common``: every candidate on the same
        episodes (episode j of a case seeded ``seed + j``; the cases' seeds are offset);
        else each candidate on its own episodes. ``collect``: a list that receives
        observation directions (every 10th step)."""
        out = []
        for c_idx, (venv, n) in enumerate(self.envs.values()):
            stride = 0 if common else n
            seeds = [
                seed + 100_000 * c_idx + stride * i + j
                for i in range(self.n_candidates)
                for j in range(n)
            ]
            obs, _ = venv.reset(seed=seeds)
            th = np.repeat(thetas, n, axis=0)
            ret = np.zeros(venv.num_envs)
            alive = np.ones(venv.num_envs, dtype=bool)
            for k in range(self.horizon):
                if collect is not None and k % 10 == 0:
                    z = np.asarray(obs, np.float64)
                    r = np.linalg.norm(z, axis=1, keepdims=True)
                    collect.append((z / np.maximum(r, 1e-12))[r[:, 0] > 0])
                v = self.v_max * LinearDirectionActor.actions(obs, th, self.features, transform)
                obs, r, term, trunc, _ = venv.step(v[:, None])
                ret += np.where(alive, r, 0.0)
                alive &= ~(term | trunc)
                if not alive.any():
                    break
            out.append(ret.reshape(self.n_candidates, n))
        return np.concatenate(out, axis=1)

    def close(self) -> None:
        for venv, _ in self.envs.values():
            venv.close()


def train_random_search(
    cfg: TrainConfig,
    seed: int,
    env_id: str,
    callback: CurveCallback | None = None,
) -> tuple[LinearDirectionActor, dict]:
    """``vrs``: ARS on the linear direction actor for ``cfg.timesteps`` env steps.

    Returns the final actor and a record (iterations, steps, |theta|)."""
    rs = RandomSearch(**cfg.model)
    rng = np.random.default_rng(seed)
    envs = _CandidateEnvs(
        env_id, cfg.load_weights, 2 * rs.n_directions, cfg.features, cfg.env_kwargs
    )
    n_obs = envs.n_obs
    dim = n_obs + 1 + (1 if cfg.features == "direction" else 0)  # features and a bias
    theta = rng.normal(0.0, rs.init_std, dim)
    transform = None
    steps, it = 0, 0
    schedule = eval_schedule(cfg.timesteps, cfg.eval_points)
    history = []

    def actor() -> LinearDirectionActor:
        return LinearDirectionActor(theta, envs.v_max, cfg.features, transform)

    def candidates(scale: float) -> tuple[np.ndarray, np.ndarray]:
        deltas = rng.normal(0.0, 1.0, (rs.n_directions, dim))
        return deltas, np.concatenate(
            [theta + scale * rs.noise * deltas, theta - scale * rs.noise * deltas]
        )

    def episode_seed() -> int:
        # the first seed of a round's episodes; the 10M left at the top keep seed + k in range
        return int(rng.integers(SEARCH_SEEDS.start, SEARCH_SEEDS.stop - 10_000_000))

    if rs.whiten and steps + envs.steps_per_round <= cfg.timesteps:
        if callback is not None and schedule.due(steps):
            callback(steps, actor())
        seen: list = []
        envs.returns(candidates(1.0)[1], episode_seed(), rs.common_episodes, None, seen)
        steps += envs.steps_per_round
        transform = whitening(np.concatenate(seen))
    while True:
        if callback is not None and schedule.due(steps):
            callback(steps, actor())
        if steps + envs.steps_per_round > cfg.timesteps:
            break
        scale = max(1.0, float(np.linalg.norm(theta)) / np.sqrt(dim)) if rs.relative else 1.0
        scale *= 1.0 - (1.0 - rs.anneal) * steps / cfg.timesteps
        deltas, cands = candidates(scale)
        R = envs.returns(cands, episode_seed(), rs.common_episodes, transform)
        steps += envs.steps_per_round
        score = (-np.log(np.maximum(-R, 1e-12)) if rs.objective == "log" else R).mean(axis=1)
        plus, minus = score[: rs.n_directions], score[rs.n_directions :]
        top = np.argsort(-np.maximum(plus, minus))[: rs.top_directions]
        std = float(np.concatenate([plus[top], minus[top]]).std()) + 1e-12
        theta = theta + scale * rs.step_size / (rs.top_directions * std) * (
            (plus[top] - minus[top]) @ deltas[top]
        )
        it += 1
        history.append((steps, float(score.mean())))
    envs.close()
    final = actor()
    return final, {
        "iterations": it,
        "steps": steps,
        "actor": final.as_dict(),
        "theta_norm": float(np.linalg.norm(theta)),
        "score_history": history[-5:],
    }
