"""The assembly of the block system (3.62) (:func:`assemble`): the PEERS block element by
element, the boundary couplings and the right-hand side, restricted to the coarse
multipliers by the prolongation P (``K = P^T K_fine P``)."""

from __future__ import annotations

import time

import ngsolve as ngs
import scipy.sparse as sp

from ..boundary import BoundaryMeshes
from ..scene import Scene
from ..sparse import to_scipy
from .couplings import coupling_forms, discrete_gap, end_lift
from .peers_block import broken_peers
from .problem import DiscreteProblem
from .spaces import Spaces


def assemble(scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes | None = None
             ) -> DiscreteProblem:
    """Assemble the block system of (3.62) for ``scene`` on ``mesh`` (``coarse``: see Spaces).

    Parameters
    ----------
    scene : Scene
        The validated scene (:func:`ngdual.scene.load_scene`).
    mesh : ngsolve.Mesh
        Its mesh, e.g. :func:`ngdual.mesh.build_mesh` of ``scene.geometry``.
    coarse : BoundaryMeshes, optional
        The coarse boundary meshes h~, h^; by default built for ``mesh``.

    Returns
    -------
    DiscreteProblem
        The matrix and right-hand side, with the index sets ``sigma``, ``mult``, ``lam_n``
        of the unknown groups and ``block(rows, cols)`` to cut out A, B, C_n.

    Examples
    --------
    >>> import ngdual as nd
    >>> scene = nd.load_scene("thesis-3.46-frictionless")
    >>> problem = nd.assemble(scene, nd.build_mesh(scene.geometry, 1))
    >>> problem.spaces.dofs()["X"], len(problem.sigma)            # Table 3.1, level 1
    (180, 180)
    """
    start = time.perf_counter()
    spaces = Spaces.build(scene, mesh, coarse)
    names = list(spaces.components)
    fes = ngs.FESpace([spaces.components[n] for n in names])
    broken = broken_peers(spaces, scene.material.lame,
                          scene.labels("neumann") + scene.labels("contact"))
    d, rhs = coupling_forms(scene, fes, names, spaces)
    for form in (d, rhs):
        if form is not None:
            form.Assemble()
    P, blocks = _prolongation(spaces, names)
    lift = end_lift(scene, spaces, fes, names)
    F = P.T @ rhs.vec.FV().NumPy()
    if d is not None:
        D = to_scipy(d.mat)
        boundary = (P.T @ D @ P).tocsr()
        # a has no entries in the multipliers' columns, where lift and the gap live
        F -= P.T @ (D @ (lift - discrete_gap(scene, spaces, fes, names)))
    else:
        boundary = sp.csr_matrix((P.shape[1], P.shape[1]))
    boundary.eliminate_zeros()
    return DiscreteProblem(scene, spaces, fes, names, P, boundary, F, blocks, lift, broken,
                           time.perf_counter() - start)


def _prolongation(spaces: Spaces, names: list[str]) -> tuple[sp.csr_matrix, dict[str, slice]]:
    """P (fine unknowns x coarse unknowns): the identity on a component without a
    prolongation, ``spaces.prolongations[name]`` on the others, block by block in the order
    of ``names``; and every component's columns.

    A run of components without a prolongation is one identity block (one sparse matrix
    instead of one per component: the same P).
    """
    parts, blocks, offset, identity = [], {}, 0, 0
    for name in names:
        p = spaces.prolongations.get(name)
        width = spaces.components[name].ndof if p is None else p.shape[1]
        blocks[name] = slice(offset, offset + width)
        offset += width
        if p is None:
            identity += width
            continue
        if identity:
            parts.append(sp.identity(identity, format="csr"))
            identity = 0
        parts.append(p)
    if identity:
        parts.append(sp.identity(identity, format="csr"))
    return sp.block_diag(parts, format="csr"), blocks
