"""The beam's physics: parameters, finite elements, assembly, the clamped model, tip loads,
and the truth plants the env simulates."""
