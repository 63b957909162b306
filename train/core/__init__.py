r"""The teacher-free benchmark (``python -m train.benchmark``).

Every algorithm learns from the env's observation and reward only: no controller,
demonstration or controller-derived reward anywhere in training, and nothing read
from the env's internals. :func:`~train.core.algos.train_algo` trains one for a fixed
env-step budget,
reports learning-curve points through a callback, and returns a policy with SB3's
``predict`` in volts.

* ``vrs`` (the recipe): vectorised random search (ARS, Mania et al. 2018, "V1-t") on
  the linear direction actor :class:`train.core.search.LinearDirectionActor`,
  :math:`V = 120\,\mathrm{clip}(w \cdot [u/|u|, \log|u|] + b, -1, 1)` (11
  parameters for the 9-value observation z: 10 weights and a bias), :math:`u = T^T z`
  with T a whitening matrix the
  agent estimates from its own first round of episodes (:func:`acld_gym.wrappers.whitening`). All
  2 x ``n_directions`` perturbed actors run side by side in the native batched env
  on the same episodes (common random numbers), and each episode's return R is
  scored as :math:`-\log(-R)` (``objective: log``), which makes loads whose returns
  differ by three decades weigh alike (reward normalisation per load).
* ``ars``: sb3-contrib's ``ARS`` (linear policy, clipped) on the direction features.
* ``ppo``, ``sac``, ``td3``, ``tqc``, ``crossq``: stable-baselines3 / sb3-contrib
  on the env of :func:`train.vec.make_vec_env`: the native batched env (``SB3VecEnv``),
  actions in [-1, 1] (:class:`train.vec.VecAgentEnv`; no residual, no shaping in the
  from-scratch recipes), optionally the direction features as the observation
  (:class:`train.vec.VecDirectionFeatures`), and ``VecNormalize``. Options for them
  (fields of :class:`train.config.TrainConfig`): ``whiten_steps``,
  a ZCA whitening of the observation estimated from the agent's own first rollouts
  (:class:`train.vec.VecWhiten`, the steps counted in the budget); for PPO the policy
  ``SplitCriticPolicy`` (the critic on its own features, e.g. quadratic ones,
  :class:`train.core.sb3_policies.SplitCriticPolicy`).

Modules, in the order of a run (the config is :mod:`train.config`, the env
:mod:`train.vec`): ``search`` (``vrs``), ``sb3_policies`` and ``sb3_train`` (the SB3
algorithms),
``algos`` (:func:`~train.core.algos.train_algo`), ``evaluate`` (ISE / LQR through the
env), ``trials`` (one run, many runs, Ray Tune), ``stats`` (IQM, bootstrap) and
``report`` (tables and learning curves). The command is :mod:`train.benchmark`.
"""
