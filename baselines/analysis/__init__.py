"""Any policy in control terms, and its score (``python -m baselines.analyze``).

One job per module, in the order of an analysis (:func:`baselines.analysis.control.analyze`
runs them all):

* :mod:`~baselines.analysis.excitation`: any per-period tip load through the env's public
  step (superposed copies of the env's own load pulse);
* :mod:`~baselines.analysis.sysid`: ERA on a pulse response, with the model order chosen
  and checked;
* :mod:`~baselines.analysis.modes`: poles, residues and which pole is "mode i";
* :mod:`~baselines.analysis.modal`: the closed-loop modes from a small tip pulse;
* :mod:`~baselines.analysis.frequency`: multisine, frequency response, peaks;
* :mod:`~baselines.analysis.compliance`: the compliance peaks against the passive beam's;
* :mod:`~baselines.analysis.linear`: a linear policy's exact loop: eigenvalues, frequency
  response, margins at the actuator;
* :mod:`~baselines.analysis.effort`: RMS voltage, reactive power, chattering, time at the
  limit;
* the score (score v2, between the passive beam (0) and the clairvoyant bound (1) on a
  published test set) is :mod:`baselines.evaluation`'s (``references`` and ``score`` here
  re-export it under their old paths);
* :mod:`~baselines.analysis.control` and :mod:`~baselines.analysis.report`: all of it for
  one policy, as JSON, text and a Bode figure.
"""
