"""Training, benchmarking, sweeping and comparing RL agents on ``ACLDBeam-v1``.

One stack, behind every command:

* ``python -m train ALGO --seed N`` trains one agent with the recipe
  ``train/recipes/ALGO.yaml`` (:mod:`train.cli`): one trial of the benchmark;
* ``python -m train.benchmark`` trains every recipe with every seed and reports IQMs
  (:mod:`train.benchmark`);
* ``python -m train.sweep`` runs seeds x learning rates of a recipe with Ray Tune
  (optional extra ``acld-gym[sweep]``);
* ``python -m train.compare`` compares the shipped agents (``train/agents/``) with
  passive, LQR, SMC, MPC and the clairvoyant bound.

The pipeline: :mod:`train.config` (the one config schema, YAML) -> :mod:`train.vec` (the
one VecEnv factory: the native vector env, voltage map, shaping, whitening, features,
normalization) -> :mod:`train.core.algos` (training: the random search or an SB3
algorithm) -> :mod:`train.core.evaluate` (the one evaluator, ISE / LQR through the env)
-> :mod:`train.core.trials` (a run and its agent) -> :mod:`train.agent` (a trained agent
with SB3's ``predict`` in volts, numpy only).
"""
