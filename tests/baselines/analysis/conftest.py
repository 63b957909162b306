"""Shared, module-scoped pieces of the analysis tests: the excitation rig (2000 periods, the
unit-pulse response averaged over 64 passive episodes) and the passive beam's bands."""

import pytest

from acld_gym.util.blas import one_blas_thread
from baselines.analysis.excitation import PulseSuperposition
from baselines.analysis.modal import passive_modes


@pytest.fixture(scope="session")
def rig():
    with one_blas_thread():
        return PulseSuperposition(n_steps=2000)


@pytest.fixture(scope="session")
def passive(rig):
    """(modes, band edges) of the passive beam, identified from the rig."""
    modes, edges, _ = passive_modes(rig)
    return modes, edges


@pytest.fixture(autouse=True)
def _one_blas_thread():
    """As the commands run: one BLAS thread (the SVDs are 10x slower on a busy machine)."""
    with one_blas_thread():
        yield
