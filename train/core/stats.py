"""The benchmark's aggregate statistics (IQM, stratified-bootstrap intervals): they live in
:mod:`acld_gym.util.stats`, which the core install's score (:mod:`baselines.evaluation.score`)
shares; this module keeps the benchmark's import path."""

from acld_gym.util.stats import iqm, iqm_with_ci, stratified_bootstrap_ci

__all__ = ["iqm", "stratified_bootstrap_ci", "iqm_with_ci"]
