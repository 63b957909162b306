"""Tests of acld_gym.physics.assembly: DOF numbering (FEASMBL order) and global assembly.

Provenance: the index bookkeeping of ``SystemMatrices03.m`` and the DOF count
``sdof = nelL*ndof1 + ((nelC+1)*ndof2 + nelC*2) + nelR*ndof1`` and ``Fd(sdof-1) = 1``
of the thesis's main script (Appendix A of
/work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt), and sec. 2.7 ("the
eighteenth row of the state vector corresponded to the transverse displacement at
the tip").
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from acld_gym.physics.assembly import assemble, number_dofs
from acld_gym.physics.params import BeamParameters, Mesh

P = BeamParameters()


def _matlab_sdof(mesh: Mesh) -> int:
    # thesis MATLAB main script: ndof1 = 3, ndof2 = 4, two z per ACLD element
    return mesh.n_before * 3 + ((mesh.n_patch + 1) * 4 + mesh.n_patch * 2) + mesh.n_after * 3


def _matlab_element_indices() -> list[list[int]]:
    """Replay the index recursion of SystemMatrices03.m for nelL=1, nelC=1, nelR=3
    (1-based, as in MATLAB)."""
    nelL, nelC, nelR = 1, 1, 3
    out, index = [], None
    for iel in range(1, nelL + nelC + nelR + 1):
        if iel <= nelL:
            index = list(range(1, 7)) if iel == 1 else index[3:6] + [i + 3 for i in index[3:6]]
        elif iel <= nelL + nelC:
            if iel == nelL + 1:
                index = (
                    index[3:6]
                    + [i + 3 for i in index[3:6]]
                    + [i + 6 for i in index[3:6]]
                    + [index[5] + 7]
                )
            else:
                index = index[4:8] + [i + 6 for i in index[4:10]]
        else:
            if iel == nelL + nelC + 1:
                index = index[4:7] + [i + 6 for i in index[4:7]]
            else:
                index = index[3:6] + [i + 3 for i in index[3:6]]
        out.append(list(index))
    return out


def test_default_dof_counts_and_clamp():
    d = number_dofs(P, Mesh())
    assert d.n_dofs == 22 == _matlab_sdof(Mesh())
    assert d.clamped == (0, 1, 2)  # MATLAB: "the first three degrees of freedom were set to zero"
    assert len(d.free) == 19
    assert_array_equal(d.free, np.arange(3, 22))


def test_default_z_dofs_and_tip_index():
    d = number_dofs(P, Mesh())
    assert d.z_dofs == (11, 12)  # MATLAB 12, 13 (1-based)
    # MATLAB Fd(sdof-1) = 1: tip w is global 21 (1-based) = 20 (0-based) -> 17 after clamp
    assert d.node_dofs[-1]["w"] == 20
    assert d.reduced_index(len(d.node_x) - 1, "w") == 17
    with pytest.raises(ValueError):
        d.reduced_index(0, "w")  # clamped


def test_default_element_indices_match_matlab_feasmbl():
    d = number_dofs(P, Mesh())
    got = [list(idx) for _, _, idx in d.elements]
    want = [[i - 1 for i in idx] for idx in _matlab_element_indices()]
    assert got == want
    assert [kind for kind, _, _ in d.elements] == ["beam", "acld", "beam", "beam", "beam"]
    # element lengths: PLL*L = 0.03, PLC*L = 0.09, PLR*L/3 = 0.06
    assert_allclose([le for _, le, _ in d.elements], [0.03, 0.09, 0.06, 0.06, 0.06], rtol=1e-12)


def test_gamma_only_on_patch_nodes():
    d = number_dofs(P, Mesh())
    has_gamma = ["gamma" in nd for nd in d.node_dofs]
    assert has_gamma == [False, True, True, False, False, False]


@pytest.mark.parametrize("mesh", [Mesh(2, 2, 6), Mesh(4, 3, 5), Mesh(0, 2, 3), Mesh(1, 4, 0)])
def test_refined_mesh_dof_counts(mesh):
    p = P
    if mesh.n_before == 0:
        p = BeamParameters(patch_start=0.0)
    if mesh.n_after == 0:
        p = BeamParameters(patch_start=0.3 - 0.09)
    d = number_dofs(p, mesh)
    n_nodes = mesh.n_before + mesh.n_patch + mesh.n_after + 1
    # 3 DOFs per node, gamma on the n_patch+1 patch nodes, 2 z per ACLD element
    predicted = 3 * n_nodes + (mesh.n_patch + 1) + 2 * mesh.n_patch
    assert d.n_dofs == predicted
    assert d.n_dofs == _matlab_sdof(mesh)
    assert len(d.free) == predicted - 3
    assert len(d.node_x) == n_nodes
    assert len(d.elements) == n_nodes - 1
    # every DOF index is used exactly once and they are 0..n-1
    all_idx = sorted([g for nd in d.node_dofs for g in nd.values()] + list(d.z_dofs))
    assert all_idx == list(range(d.n_dofs))


def test_mesh_2_2_6_numbers():
    d = number_dofs(P, Mesh(2, 2, 6))
    assert d.n_dofs == 40
    assert len(d.free) == 37
    assert d.reduced_index(len(d.node_x) - 1, "w") == 40 - 2 - 3  # w before theta of last node


def test_each_acld_element_has_own_z_dofs():
    d = number_dofs(P, Mesh(2, 4, 6))
    acld = [(le, idx) for kind, le, idx in d.elements if kind == "acld"]
    assert len(acld) == 4
    zs = [idx[-2:] for _, idx in acld]
    flat = [z for pair in zs for z in pair]
    assert len(set(flat)) == 8  # no sharing between elements
    assert tuple(flat) == d.z_dofs
    node_dofs = {g for nd in d.node_dofs for g in nd.values()}
    assert not node_dofs & set(flat)
    for _, idx in acld:
        assert len(idx) == 10
        # z follow the DOFs of the element's right-hand node (FEASMBL order)
        assert idx[8] == idx[7] + 1 and idx[9] == idx[8] + 1


@pytest.mark.parametrize("mesh", [Mesh(), Mesh(2, 2, 6), Mesh(3, 5, 7)])
def test_node_positions(mesh):
    d = number_dofs(P, mesh)
    x = np.asarray(d.node_x)
    assert x[0] == 0.0
    assert_allclose(x[-1], P.length, rtol=1e-13)
    assert np.all(np.diff(x) > 0)
    assert_allclose(sum(le for _, le, _ in d.elements), P.length, rtol=1e-13)
    assert_allclose(np.diff(x), [le for _, le, _ in d.elements], rtol=1e-12)
    # patch boundaries are nodes
    assert_allclose(x[mesh.n_before], P.patch_start, rtol=1e-12)
    assert_allclose(x[mesh.n_before + mesh.n_patch], P.patch_start + P.patch_length, rtol=1e-12)


def test_mesh_section_mismatch_rejected():
    with pytest.raises(ValueError):
        number_dofs(P, Mesh(0, 1, 3))  # 0.03 m before the patch but no element there
    with pytest.raises(ValueError):
        number_dofs(BeamParameters(patch_start=0.0), Mesh(1, 1, 3))  # element on 0-length span


@pytest.mark.parametrize("mesh", [Mesh(), Mesh(2, 3, 4)])
def test_global_matrices_symmetric_and_rigid_modes(mesh):
    d = number_dofs(P, mesh)
    M, C, K, Pc = assemble(P, d)
    for A in (M, C, K):
        assert_allclose(A, A.T, rtol=0, atol=1e-14 * np.abs(A).max())
    np.linalg.cholesky(M)
    # unclamped structure: three rigid-body modes (u, w translation, w = x*theta rotation),
    # gamma = z = 0
    x = np.asarray(d.node_x)
    R = np.zeros((d.n_dofs, 3))
    for xi, nd in zip(x, d.node_dofs, strict=True):
        R[nd["u"], 0] = 1.0
        R[nd["w"], 1] = 1.0
        R[nd["theta"], 2] = 1.0
        R[nd["w"], 2] = xi
    assert_allclose(K @ R, 0.0, atol=1e-12 * np.abs(K).max())
    ev = np.linalg.eigvalsh(K)
    assert np.sum(np.abs(ev) < 1e-12 * ev.max()) == 3
    # total transverse mass = beam + layers on the patch (Euler-Bernoulli lumped total)
    total = (
        P.beam_density * P.beam_area * P.length
        + (P.pzt_density * P.pzt_area + P.vem_density * P.vem_area) * P.patch_length
    )
    assert_allclose(R[:, 1] @ M @ R[:, 1], total, rtol=1e-12)
    assert_allclose(R[:, 0] @ M @ R[:, 0], total, rtol=1e-12)
    # piezo force: self-equilibrated (no net axial force / moment on the free structure)
    assert_allclose(R.T @ Pc, 0.0, atol=1e-12 * np.abs(Pc).max())


def test_piezo_vector_assembled_only_at_patch_end_nodes():
    # Pc of adjacent ACLD elements cancels at interior patch nodes (constant E_c d31 b V
    # force in the PZT): only the two patch end nodes are loaded.
    mesh = Mesh(2, 3, 4)
    d = number_dofs(P, mesh)
    _, _, _, Pc = assemble(P, d)
    loaded = {
        n
        for n, nd in enumerate(d.node_dofs)
        if np.any(np.abs(Pc[list(nd.values())]) > 1e-12 * np.abs(Pc).max())
    }
    assert loaded == {mesh.n_before, mesh.n_before + mesh.n_patch}
    assert_array_equal(Pc[list(d.z_dofs)], 0.0)
