"""Training, sweeping and comparing RL agents on ``ACLDBeam-v1``.

* ``python -m train ppo|sac ...`` trains one agent (:mod:`train.cli`), with the
  hyperparameters of ``train/ppo.yaml`` / ``train/sac.yaml``.
* ``python -m train.compare`` compares the shipped agents (``train/agents/``)
  with passive, LQR, SMC, MPC and the clairvoyant bound.
* ``python -m train.sweep`` runs seeds / hyperparameters with Ray Tune
  (optional extra ``acld-gym[sweep]``).

The pipeline: :mod:`train.config` (YAML) -> :mod:`train.vec` (the native vector
env, voltage rescaling, shaping, normalization) -> :mod:`train.callbacks`
(evaluation on the thesis cases, physics metrics, checkpoints) ->
:mod:`train.agent` (a trained agent with SB3's ``predict`` in volts).
"""
