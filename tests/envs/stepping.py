"""Shared by the step tests: single envs driven side by side as a vector env would drive
them (tests/envs/test_batch.py, tests/envs/test_vector_env.py)."""

from __future__ import annotations

import numpy as np

from acld_gym.envs.beam_env import ACLDBeamEnv


def single_rollout(kw: dict, n: int, acts, seed: int = 11, compiled: bool | None = None):
    """``n`` single envs driven as a NEXT_STEP vector env would be (env i reset with
    ``seed + i``, reset again after its episode ends); ``compiled`` forces the step (None:
    the default). Returns per step ``(obs, reward, terminated, truncated, infos)``."""
    envs = [ACLDBeamEnv(**kw) for _ in range(n)]
    if compiled is not None:
        for e in envs:
            e.compiled_step = compiled
    return drive(envs, acts, seed)


def drive(envs, acts, seed: int):
    """``envs`` (single envs, wrapped or not) driven as a NEXT_STEP vector env drives its
    sub-envs: env i reset with ``seed + i``, reset again after its episode ends. Returns per
    step ``(obs, reward, terminated, truncated, infos)``, the first (the resets) with None
    for reward and flags."""
    n = len(envs)
    out = [e.reset(seed=seed + i) for i, e in enumerate(envs)]
    steps = [(np.array([o for o, _ in out]), None, None, None, [i for _, i in out])]
    done = [False] * n
    for a in acts:
        rows = []
        for i, e in enumerate(envs):
            if done[i]:
                o, info = e.reset()
                r, te, tr = 0.0, False, False
            else:
                o, r, te, tr, info = e.step(a[i])
            done[i] = te or tr
            rows.append((o, r, te, tr, info))
        o, r, te, tr, info = zip(*rows, strict=True)
        steps.append((np.array(o), np.array(r), np.array(te), np.array(tr), list(info)))
    return steps
