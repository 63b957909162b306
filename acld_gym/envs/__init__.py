"""The Gymnasium environments: episode ingredients, the fused step, checks, the single and
batched envs, v0, rendering and the SB3 adapter."""
