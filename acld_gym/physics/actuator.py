"""The piezoelectric patch as the actuator: its voltage limit.

``V_LIMIT`` is the largest voltage the patch takes in the thesis's saturated runs (sec. 5.3,
"Saturation limits of 120V to -120V were enforced to replicate realistic voltage
constraints"): the env's action bound, the baselines' and the bound's limit.
"""

from __future__ import annotations

__all__ = ["V_LIMIT"]

#: Voltage limit of the PZT patch [V] (thesis sec. 5.3).
V_LIMIT = 120.0
