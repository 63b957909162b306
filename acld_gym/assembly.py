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

import numpy as np

from .elements import ACLD_NODE_DOFS, BEAM_NODE_DOFS, acld_element, timoshenko_element
from .params import BeamParameters, Mesh

__all__ = ["DofMap", "number_dofs", "assemble"]


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

    @property
    def free(self) -> np.ndarray:
        """Global DOFs that remain after clamping, in order."""
        return np.setdiff1d(np.arange(self.n_dofs), self.clamped)

    def reduced_index(self, node: int, dof: str) -> int:
        """Index of a nodal DOF in the clamped system (raises if it is clamped)."""
        g = self.node_dofs[node][dof]
        hits = np.flatnonzero(self.free == g)
        if hits.size == 0:
            raise ValueError(f"DOF {dof!r} of node {node} is clamped")
        return int(hits[0])


def number_dofs(p: BeamParameters, mesh: Mesh) -> DofMap:
    """Number the DOFs of the mesh in the thesis's (FEASMBL) order."""
    sections = [("beam", p.patch_start, mesh.n_before, "n_before"),
                ("acld", p.patch_length, mesh.n_patch, "n_patch"),
                ("beam", p.length - p.patch_start - p.patch_length, mesh.n_after, "n_after")]
    kinds: list[str] = []
    lengths: list[float] = []
    for kind, span, count, name in sections:
        if count > 0 and span <= 1e-12 * p.length:
            raise ValueError(f"Mesh.{name} = {count} but that section is {span:g} m long "
                             f"(set {name}=0)")
        if count == 0 and span > 1e-12 * p.length:
            raise ValueError(f"Mesh.{name} = 0 but that section is {span:g} m long "
                             f"(needs at least one element)")
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
    return DofMap(node_x=node_x, node_dofs=tuple(node_dofs), elements=tuple(elements),
                  z_dofs=tuple(z_dofs), n_dofs=nxt)


def assemble(p: BeamParameters, dofs: DofMap) -> tuple[np.ndarray, ...]:
    """Global ``(M, C, K, Pc)`` before the clamp (FEASMBL / FEASMBL2).

    Element matrices are computed once per distinct (kind, length).
    """
    n = dofs.n_dofs
    M, C, K = (np.zeros((n, n)) for _ in range(3))
    Pc = np.zeros(n)
    cache: dict[tuple[str, float], object] = {}
    for kind, le, idx in dofs.elements:
        key = (kind, round(le, 15))
        if key not in cache:
            cache[key] = (acld_element if kind == "acld" else timoshenko_element)(p, le)
        em = cache[key]
        ix = np.ix_(idx, idx)
        M[ix] += em.M
        C[ix] += em.C
        K[ix] += em.K
        Pc[list(idx)] += em.Pc
    return M, C, K, Pc
