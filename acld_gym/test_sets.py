r"""The benchmark's published test sets: the episodes a policy's score is computed on.

A policy's score (:mod:`baselines.evaluation.score`, score v2) is the interquartile mean over
these episodes of :math:`(ISE_{passive} - ISE) / (ISE_{passive} - ISE_{bound})`: the passive
beam 0, the clairvoyant bound 1 on every level. Each env id has its test
set, versioned with it: the seeds below, reset as ``env.reset(seed=s)`` with
``load_case="random"``, draw the load (and, with ``param_noise``, the plant) and the
sensor noise of each episode. A change of an env's random-load generator or of the seeds
is a new version of its test set, and scores of different versions are not comparable.

The seeds are disjoint from every seed used to train or select the shipped policies:

* training: SB3 runs seed sub-env i with ``seed + i`` (a few thousand at most); the random
  search (``train.core.search``) draws its episode seeds from [1_000_000, 2**31);
* model selection: the thesis cases (seed 0), the held-out random loads
  :data:`HELDOUT_SEEDS` = [100_000, 100_020) and the validation loads the recipes select
  their runs on, from :data:`VALIDATION_SEED0` = 200_000 (256 at most);
* the engineer's designs (:mod:`baselines.engineer`): their filter noise models are chosen
  offline on the training plants [3_000_000, 3_000_100).

The block [500_000, 600_000) is reserved for test sets: training and model selection must
not use it. Every registered id (:data:`acld_gym.envs.presets.PRESETS`) has its entry in
:data:`TEST_SETS`; a new one gets its own before it can be scored. On the presets with
parameter noise and temperature draws (``ACLDBeamHard-v1``) each episode's references are
computed on that episode's own plant: LQR and the other policies run on it with the nominal
design, and the bound (:func:`baselines.evaluate.bound_episode`) is solved for it, with the
preset's actuator inside.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "EvaluationSet",
    "TEST_SETS",
    "TEST_SEEDS",
    "RESERVED_SEEDS",
    "HELDOUT_SEEDS",
    "VALIDATION_SEED0",
    "validation_seeds",
    "evaluation_set",
]

#: Seeds reserved for test sets (never for training or model selection).
RESERVED_SEEDS = range(500_000, 600_000)

#: Seeds of the held-out random-load episodes every policy's ISE relative to the thesis LQR
#: is reported on (``python -m train.compare``, the benchmark's ``random`` column,
#: :func:`train.scoring.score`), beside the thesis cases 1, 2, 3 with seed 0; disjoint from
#: the validation loads and from :data:`RESERVED_SEEDS`. (Also importable from
#: ``train.core.evaluate``.)
HELDOUT_SEEDS: tuple[int, ...] = tuple(range(100_000, 100_020))

#: First seed of the validation loads (random loads the recipes select checkpoints and runs
#: on): seeds from here on, disjoint from :data:`HELDOUT_SEEDS` and the test sets.
VALIDATION_SEED0 = 200_000


def validation_seeds(n: int) -> tuple[int, ...]:
    """The first ``n`` validation seeds (random loads), from :data:`VALIDATION_SEED0`."""
    return tuple(range(VALIDATION_SEED0, VALIDATION_SEED0 + int(n)))


@dataclass(frozen=True)
class EvaluationSet:
    """A published set of test episodes of one env id."""

    env_id: str
    """Gymnasium id of the env the episodes are drawn from."""
    version: int
    """Version of the set; a new one whenever its episodes change."""
    seeds: tuple[int, ...]
    """Reset seeds, one per episode, in :data:`RESERVED_SEEDS`."""
    load_case: str = "random"
    """The env's ``load_case`` for every episode."""

    def __post_init__(self):
        if not self.seeds or len(set(self.seeds)) != len(self.seeds):
            raise ValueError("EvaluationSet.seeds must be distinct, and at least one")
        outside = [s for s in self.seeds if s not in RESERVED_SEEDS]
        if outside:
            raise ValueError(
                f"EvaluationSet.seeds must lie in the reserved block "
                f"[{RESERVED_SEEDS.start}, {RESERVED_SEEDS.stop}), got {outside[:3]}"
            )

    @property
    def name(self) -> str:
        """``"<env id>/test-v<version>"``."""
        return f"{self.env_id}/test-v{self.version}"

    def first(self, n: int) -> EvaluationSet:
        """The set of the first ``n`` episodes (a reduced run: not the published score)."""
        if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= len(self.seeds):
            raise ValueError(f"n must be an integer in [1, {len(self.seeds)}], got {n!r}")
        return EvaluationSet(self.env_id, self.version, self.seeds[:n], self.load_case)


_SEEDS_V1 = tuple(range(500_000, 500_100))

#: The test set of each env id (100 random-load episodes each). v1 and v0 share their seeds
#: (the same loads' draws on two meshes); each difficulty preset has its own block, since
#: its seeds also draw its plant (temperature, parameters) and its sensor noise.
TEST_SETS: dict[str, EvaluationSet] = {
    "ACLDBeam-v1": EvaluationSet("ACLDBeam-v1", 1, _SEEDS_V1),
    "ACLDBeam-v0": EvaluationSet("ACLDBeam-v0", 1, _SEEDS_V1),
    "ACLDBeamLab-v1": EvaluationSet("ACLDBeamLab-v1", 1, tuple(range(500_100, 500_200))),
    "ACLDBeamHard-v1": EvaluationSet("ACLDBeamHard-v1", 1, tuple(range(500_200, 500_300))),
}

#: The test seeds of each env id (:data:`TEST_SETS`).
TEST_SEEDS: dict[str, tuple[int, ...]] = {k: v.seeds for k, v in TEST_SETS.items()}


def evaluation_set(env_id: str) -> EvaluationSet:
    """The test set of ``env_id`` (``ValueError`` naming the known ids)."""
    if env_id not in TEST_SETS:
        raise ValueError(
            f"env_id: no published test set for {env_id!r}; known: {sorted(TEST_SETS)}"
        )
    return TEST_SETS[env_id]
