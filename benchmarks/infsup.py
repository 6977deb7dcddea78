"""Discrete inf-sup constants of the boundary multiplier spaces (phi on Gamma_N, lambda on Gamma_C).

    beta_h = inf_{mu in N_h x C_h x C_h} sup_{tau in X_h} d(mu, tau) / (|mu|_{1/2} ||tau||_{H(div)})

with d = d_N + d_{C,t} + d_{C,n} of (3.24), X_h the PEERS stresses and |mu|_{1/2} the discrete
H^{1/2} norm of the coarse P1 multipliers (the interpolation norm between L^2 and H^1 of
every boundary part: M V diag((1 + k^2)^{1/2}) V^T M from the eigenpairs (k^2, V) of the
arc-length stiffness against the mass matrix). beta_h^2 is the smallest eigenvalue of
B^T A^{-1} B against that norm (A the H(div) Gram matrix of X_h, B = K[sigma, multipliers]).
It must stay bounded away from zero under refinement, with fixed ends (the thesis), with
free ends next to Gamma_N and at kinks (``contact.ends = "consistent"``).

    python benchmarks/infsup.py --scenes hertz-cylinder flat-punch wedge --levels 1 2 3 4 5
"""

from __future__ import annotations

import argparse
import json
import time

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ngdual import peers
from ngdual.forms import Spaces, assemble
from ngdual.io import versions
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene

DEFAULT_SCENES = ("thesis-3.46-frictionless", "hertz-cylinder", "flat-punch", "wedge")


def hdiv_gram(mesh: ngs.Mesh) -> sp.csr_matrix:
    """int sigma : tau + div sigma . div tau on X_h (the dof order of :mod:`ngdual.forms`)."""
    comps = peers.peers_spaces(mesh)
    fes = ngs.FESpace([comps[c] for c in peers.STRESS])
    (r1, r2, b1, b2), (s1, s2, c1, c2) = fes.TnT()
    sig, tau = peers.stress(r1, r2, b1, b2), peers.stress(s1, s2, c1, c2)
    a = ngs.BilinearForm(fes)
    a += (ngs.InnerProduct(sig, tau) + peers.stress_divergence(r1, r2)
          * peers.stress_divergence(s1, s2)) * ngs.dx
    a.Assemble()
    rows, cols, vals = a.mat.COO()
    return sp.csr_matrix((np.asarray(vals), (np.asarray(rows), np.asarray(cols))),
                         shape=(fes.ndof, fes.ndof))


def half_norm(coarse) -> np.ndarray:
    """The discrete H^{1/2} norm matrix of one coarse P1 space."""
    mass, stiff = coarse.p1_mass_stiffness()
    vals, vecs = sla.eigh(stiff, mass)
    mv = mass @ vecs
    return (mv * np.sqrt(1.0 + np.maximum(vals, 0.0))) @ mv.T


def infsup(scene, level: int) -> dict:
    """beta_h of the boundary multipliers of ``scene`` on ``level``."""
    start = time.perf_counter()
    problem = assemble(scene, build_mesh(scene.geometry, level))
    spaces: Spaces = problem.spaces
    norms, names = [], []
    if spaces.neumann is not None:
        n = half_norm(spaces.neumann)
        norms += [n, n]
        names += ["phi1", "phi2"]
    if spaces.contact is not None:
        n = half_norm(spaces.contact)
        norms += [n, n]
        names += ["lam_t", "lam_n"]
    B = problem.block(problem.sigma, problem.index(*names)).toarray()
    A = hdiv_gram(problem.fes.mesh)
    assert A.shape[0] == len(problem.sigma)
    solve = spla.factorized(A.tocsc())
    AinvB = np.column_stack([solve(B[:, j]) for j in range(B.shape[1])])
    S = B.T @ AinvB
    N = sla.block_diag(*norms)
    beta2 = sla.eigh(0.5 * (S + S.T), N, eigvals_only=True, subset_by_index=[0, 0])[0]
    return {"scene": scene.name, "ends": scene.contact.ends, "level": level,
            "multipliers": int(B.shape[1]), "stresses": int(A.shape[0]),
            "beta": float(np.sqrt(max(beta2, 0.0))), "seconds": time.perf_counter() - start}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=list(DEFAULT_SCENES))
    parser.add_argument("--levels", nargs="+", type=int, default=[1, 2, 3, 4, 5])
    parser.add_argument("--set", action="append", default=[], dest="overrides")
    parser.add_argument("--json", help="write the table to this file")
    args = parser.parse_args(argv)
    rows = []
    print(f"{'scene':28s} {'ends':10s} {'level':>5s} {'mult':>6s} {'X_h':>8s} {'beta_h':>8s}")
    for name in args.scenes:
        scene = load_scene(name, args.overrides)
        for level in args.levels:
            row = infsup(scene, level)
            rows.append(row)
            print(f"{row['scene']:28s} {row['ends']:10s} {level:5d} {row['multipliers']:6d} "
                  f"{row['stresses']:8d} {row['beta']:8.4f}", flush=True)
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"rows": rows, "versions": versions()}, out, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
