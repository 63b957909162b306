"""The retry threshold of a recipe with several runs per seed (``restart_above``): a run is
followed by the next only while its selected check's validation cost is above it.

A threshold is relative to a reference controller's cost on the *same* validation loads by
the *same* evaluator (:func:`train.core.evaluate.validation_cost`), computed on the level
the run trains on, so one recipe carries over to every registered id:
``restart_above: 1.0299 * lqg`` retries a run whose cost is more than 2.99 % above the
level's engineer's LQG (:class:`baselines.engineer.DelayLQGPolicy`, the level's design).

The references (:data:`REFERENCES`):

* ``lqg``, the anchor of the recipes: designed for each level's actuator and sensor, it
  controls every level (on the Hard level's scatter of plants too) and sits where a sound
  run ends (the issue's goal is the engineer's level); 256 episodes take ~1-3 s;
* ``lqr``, the thesis LQR: a bad anchor where it limit-cycles (``ACLDBeamLab-v1``: its
  validation cost 1.31, worse than no control), kept for the records of acld-gym
  0.7.0-0.17.1 (``restart_above: lqr``);
* ``passive``, no control: the cost is already per load relative to the passive beam's
  (1 on every load of a level whose plant is the nominal one), so ``r * passive`` is
  a plain fraction of no control, which does not carry over (a sound run is at ~0.52 on
  ``ACLDBeam-v1``, ~0.60 on the lab rig, ~0.9 on the Hard level).

A bare number (``restart_above: 0.520``) is an absolute validation cost, and every such
number in the package's history was calibrated on :data:`ABSOLUTE_LEVEL`: it is accepted
there, so the ablations and committed records of v1 stay valid and reproducible, and
refused on any other level (:meth:`RestartRule.check_level`), which it would silently turn
into "every run, always" (acld-gym 0.19: 0.520 on the lab rig, where no run reaches it).
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass

__all__ = ["ABSOLUTE_LEVEL", "REFERENCES", "RestartRule", "reference_cost"]

#: The references a threshold may be relative to.
REFERENCES = ("lqg", "lqr", "passive")
#: The level every bare-number threshold was calibrated on (the only one there was).
ABSOLUTE_LEVEL = "ACLDBeam-v1"
_RELATIVE = re.compile(r"^\s*(?:(?P<ratio>[^*\s]+)\s*\*\s*)?(?P<ref>[A-Za-z_]+)\s*$")
_EXPECTED = (
    f"'<ratio> * <reference>' with a reference of {list(REFERENCES)} (e.g. '1.03 * lqg'), "
    f"a reference alone (ratio 1), a number (a validation cost of {ABSOLUTE_LEVEL} only) "
    "or null"
)


@dataclass(frozen=True)
class RestartRule:
    """A parsed ``restart_above``: ``ratio`` times ``reference``'s validation cost, or
    (``reference`` None) the absolute cost ``ratio`` of :data:`ABSOLUTE_LEVEL`."""

    ratio: float
    reference: str | None

    @classmethod
    def parse(cls, value, name: str = "restart_above") -> RestartRule | None:
        """The rule of a config's value (None: no threshold); ``ValueError`` naming
        ``name`` and the forms expected."""
        if value is None:
            return None
        if isinstance(value, str):
            m = _RELATIVE.match(value)
            if m is None or m["ref"] not in REFERENCES:
                raise ValueError(f"{name} must be {_EXPECTED}; got {value!r}")
            try:
                ratio = 1.0 if m["ratio"] is None else float(m["ratio"])
            except ValueError:
                raise ValueError(f"{name}: the ratio must be a number, got {value!r}") from None
            if not (math.isfinite(ratio) and ratio > 0):
                raise ValueError(f"{name}: the ratio must be finite and > 0, got {value!r}")
            return cls(ratio, m["ref"])
        from acld_gym.util.validate import check_real

        try:
            return cls(check_real(name, value, 0.0, None, low_open=True), None)
        except ValueError as exc:
            raise ValueError(f"{exc}; expected {_EXPECTED}") from None

    def __str__(self) -> str:
        if self.reference is None:
            return f"{self.ratio:g} (a validation cost of {ABSOLUTE_LEVEL})"
        return f"{self.ratio:g} * {self.reference}"

    def check_level(self, env_id: str, name: str = "restart_above") -> None:
        """``ValueError`` if the rule is a bare number and ``env_id`` is not the level it
        was calibrated on (module docstring); nothing is computed."""
        if self.reference is None and env_id != ABSOLUTE_LEVEL:
            raise ValueError(
                f"{name}: {self.ratio:g} is an absolute validation cost, calibrated on "
                f"{ABSOLUTE_LEVEL}; on {env_id} give it relative to the level's reference "
                f"on the same loads, e.g. '1.03 * lqg' ({_EXPECTED})"
            )

    def resolve(self, env_id: str, seeds) -> dict:
        """The threshold on ``env_id``'s validation loads ``seeds`` (those the runs are
        selected on): ``{"threshold", "rule", "ratio", "reference", "reference_cost",
        "loads"}`` (a bare number: its value, no reference cost)."""
        self.check_level(env_id)
        out = {"rule": str(self), "ratio": self.ratio, "reference": self.reference}
        out["loads"] = len(seeds)
        if self.reference is None:
            return {"threshold": self.ratio, **out, "reference_cost": None}
        cost = reference_cost(self.reference, env_id, tuple(seeds))
        return {"threshold": self.ratio * cost, **out, "reference_cost": cost}


@functools.lru_cache(maxsize=16)
def reference_cost(reference: str, env_id: str, seeds: tuple) -> float:
    """:func:`train.core.evaluate.validation_cost` of ``reference`` (:data:`REFERENCES`)
    designed on ``env_id`` (its nominal model and the level's design), on ``seeds`` (a
    tuple); computed once per process for the same arguments (a benchmark resolves the same
    rule for every seed it runs)."""
    from baselines.engineer import DelayLQGPolicy
    from baselines.policies import LQRPolicy, PassivePolicy

    from .evaluate import _make_env, validation_cost

    env = _make_env(env_id, 1)
    make = {"lqg": DelayLQGPolicy, "lqr": LQRPolicy, "passive": PassivePolicy}[reference]
    return validation_cost(make.for_env(env), env_id, seeds)
