"""Assembly of element matrices into the global system for a general mesh.

The beam is split into ``n_before`` Timoshenko elements between the clamp and
the patch, ``n_patch`` ACLD elements on the patch and ``n_after`` Timoshenko
elements to the tip. Nodes touched by an ACLD element carry four DOFs
``(u, w, theta, gamma)``, the others three ``(u, w, theta)``; each ACLD
element's two GHM coordinates follow the DOFs of its right-hand node. This is
exactly the numbering of ``SystemMatrices03.m`` (FEASMBL), so the default
1 + 1 + 3 mesh has 22 DOFs, 19 after clamping, with the tip deflection at
index 17 (0-based).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from acld_gym.physics.elements import (
    ACLD_NODE_DOFS,
    BEAM_NODE_DOFS,
    acld_terms,
    combine_terms,
    timoshenko_terms,
)
from acld_gym.physics.params import BeamParameters, Mesh

__all__ = ["DofMap", "AssembledTerms", "number_dofs", "assemble", "assemble_terms"]


@dataclass(frozen=True)
class DofMap:
    """Global DOF numbering (before the clamp is applied).

    Attributes
    ----------
    node_x : node positions [m].
    node_dofs : per node, a dict from DOF name to global index.
    elements : per element, ``(kind, length, global_indices)`` with kind
        ``"beam"`` or ``"acld"``.
    z_dofs : global indices of the GHM coordinates, two per ACLD element.
    n_dofs : total number of DOFs.
    """

    node_x: tuple[float, ...]
    node_dofs: tuple[dict[str, int], ...]
    elements: tuple[tuple[str, float, tuple[int, ...]], ...]
    z_dofs: tuple[int, ...]
    n_dofs: int

    @property
    def clamped(self) -> tuple[int, ...]:
        """Global DOFs fixed by the clamp at x = 0: u, w and theta of node 0."""
        return tuple(self.node_dofs[0][k] for k in BEAM_NODE_DOFS)

    @cached_property
    def free(self) -> np.ndarray:
        """Global DOFs that remain after clamping, in order (read-only)."""
        free = np.setdiff1d(np.arange(self.n_dofs), self.clamped)
        free.setflags(write=False)
        return free

    @cached_property
    def _reduced(self) -> dict[int, int]:
        return {int(g): i for i, g in enumerate(self.free)}

    def reduced_index(self, node: int, dof: str) -> int:
        """Index of a nodal DOF in the clamped system (raises if it is clamped)."""
        g = self.node_dofs[node][dof]
        if g not in self._reduced:
            raise ValueError(f"DOF {dof!r} of node {node} is clamped")
        return self._reduced[g]

    def reduced_of(self, g: int) -> int:
        """Index of global DOF ``g`` in the clamped system (raises if it is clamped)."""
        if g not in self._reduced:
            raise ValueError(f"global DOF {g} is clamped")
        return self._reduced[g]


def number_dofs(p: BeamParameters, mesh: Mesh) -> DofMap:
    """Number the DOFs of the mesh in the thesis's (FEASMBL) order."""
    sections = [
        ("beam", p.patch_start, mesh.n_before, "n_before"),
        ("acld", p.patch_length, mesh.n_patch, "n_patch"),
        ("beam", p.length - p.patch_start - p.patch_length, mesh.n_after, "n_after"),
    ]
    kinds: list[str] = []
    lengths: list[float] = []
    for kind, span, count, name in sections:
        if count > 0 and span <= 1e-12 * p.length:
            raise ValueError(
                f"Mesh.{name} = {count} but that section is {span:g} m long (set {name}=0)"
            )
        if count == 0 and span > 1e-12 * p.length:
            raise ValueError(
                f"Mesh.{name} = 0 but that section is {span:g} m long (needs at least one element)"
            )
        kinds += [kind] * count
        lengths += [span / count] * count if count else []
    n_nodes = len(kinds) + 1
    acld_node = [False] * n_nodes
    for e, kind in enumerate(kinds):
        if kind == "acld":
            acld_node[e] = acld_node[e + 1] = True

    node_dofs: list[dict[str, int]] = []
    z_dofs: list[int] = []
    elem_z: dict[int, tuple[int, int]] = {}
    nxt = 0
    for n in range(n_nodes):
        names = ACLD_NODE_DOFS if acld_node[n] else BEAM_NODE_DOFS
        node_dofs.append({name: nxt + i for i, name in enumerate(names)})
        nxt += len(names)
        if n > 0 and kinds[n - 1] == "acld":  # z of the element ending at this node
            elem_z[n - 1] = (nxt, nxt + 1)
            z_dofs += [nxt, nxt + 1]
            nxt += 2

    elements = []
    for e, (kind, le) in enumerate(zip(kinds, lengths, strict=True)):
        names = ACLD_NODE_DOFS if kind == "acld" else BEAM_NODE_DOFS
        idx = [node_dofs[e][k] for k in names] + [node_dofs[e + 1][k] for k in names]
        if kind == "acld":
            idx += list(elem_z[e])
        elements.append((kind, le, tuple(idx)))
    node_x = tuple(np.concatenate([[0.0], np.cumsum(lengths)]).tolist())
    return DofMap(
        node_x=node_x,
        node_dofs=tuple(node_dofs),
        elements=tuple(elements),
        z_dofs=tuple(z_dofs),
        n_dofs=nxt,
    )


@dataclass(frozen=True, eq=False)
class AssembledTerms:
    """Global unit matrices of every term (sparse CSR, all DOFs before the clamp) and the
    piezo unit vector; :meth:`combine` weights them with a parameter set's material
    coefficients (:data:`acld_gym.physics.elements.TERM_COEFFICIENTS`)."""

    units: dict[str, sp.csr_matrix]
    piezo: np.ndarray

    def combine(self, p: BeamParameters):
        """Global sparse ``(M, C, K)`` and dense ``Pc`` for the material parameters of ``p``."""
        return combine_terms(self.units, self.piezo, p)


def assemble_terms(p: BeamParameters, dofs: DofMap) -> AssembledTerms:
    """Assemble each term's unit matrices into global sparse matrices (FEASMBL order).

    Unit matrices depend on the geometry only; they are computed once per distinct
    (kind, length).
    """
    n = dofs.n_dofs
    rows: dict[str, list] = {}
    cols: dict[str, list] = {}
    vals: dict[str, list] = {}
    piezo = np.zeros(n)
    cache: dict[tuple[str, float], object] = {}
    for kind, le, idx in dofs.elements:
        key = (kind, round(le, 15))
        if key not in cache:
            cache[key] = (acld_terms if kind == "acld" else timoshenko_terms)(p, le)
        et = cache[key]
        ii = np.asarray(idx)
        r = np.repeat(ii, ii.size)
        c = np.tile(ii, ii.size)
        for name, U in et.units.items():
            rows.setdefault(name, []).append(r)
            cols.setdefault(name, []).append(c)
            vals.setdefault(name, []).append(U.ravel())
        np.add.at(piezo, ii, et.piezo)
    units = {
        name: sp.coo_matrix(
            (np.concatenate(vals[name]), (np.concatenate(rows[name]), np.concatenate(cols[name]))),
            shape=(n, n),
        ).tocsr()
        for name in rows
    }
    return AssembledTerms(units=units, piezo=piezo)


def assemble(p: BeamParameters, dofs: DofMap) -> tuple[np.ndarray, ...]:
    """Global dense ``(M, C, K, Pc)`` before the clamp (FEASMBL / FEASMBL2)."""
    M, C, K, Pc = assemble_terms(p, dofs).combine(p)
    return M.toarray(), C.toarray(), K.toarray(), Pc
