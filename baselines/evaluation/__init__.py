"""The evaluation protocol: how any policy is measured, from one subpackage.

* :mod:`~baselines.evaluation.seeds`: every seed block -- training, selection (held-out
  and validation loads), test (the published test sets) -- importable from one place;
* :mod:`~baselines.evaluation.rollout`: one deterministic episode of any policy with SB3's
  ``predict``, the clairvoyant bound's episode, and an episode's row of metrics;
* :mod:`~baselines.evaluation.cache`: the one cache of the references (format, key,
  validation, atomic replacement);
* :mod:`~baselines.evaluation.references`: a test set's per-episode references (passive,
  thesis LQR, bound), cached;
* :mod:`~baselines.evaluation.score`: score v2 on a test set (passive 0, bound 1);
* :mod:`~baselines.evaluation.ise`: the thesis-facing view, ISE relative to the thesis LQR
  on cases 1, 2, 3 and the held-out random loads, and every reference's ISE per case.

The command lines are apart: ``python -m baselines.evaluate`` (the references' tables),
``python -m baselines.analyze`` (one policy in control terms), ``python -m train.compare``.
``train`` imports this subpackage; it imports nothing of ``train``. The old import paths
:mod:`baselines.rollout`, :mod:`baselines.analysis.references` and
``baselines.analysis.score`` re-export their public names (the same objects).
"""
