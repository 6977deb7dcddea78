"""Discrete inf-sup constants of the boundary multiplier spaces, phi on Gamma_N and lambda on
Gamma_C (``ngdual bench infsup``).

    beta_h = inf_{mu in N_h x C_h x C_h} sup_{tau in X_h} d(mu, tau) / (|mu|_{1/2} ||tau||_{H(div)})

with d = d_N + d_{C,t} + d_{C,n} of (3.24), X_h the PEERS stresses and |mu|_{1/2} the discrete
H^{1/2} norm of the coarse P1 multipliers (the interpolation norm between L^2 and H^1 of
every boundary part: M V diag((1 + k^2)^{1/2}) V^T M from the eigenpairs (k^2, V) of the
arc-length stiffness against the mass matrix). beta_h^2 is the smallest eigenvalue of
B^T A^{-1} B against that norm (A the H(div) Gram matrix of X_h,
:func:`ngdual.verification.infsup.gram_matrix`; B = K[sigma, multipliers]).
It must stay bounded away from zero under refinement, with fixed ends (the thesis), with
free ends next to Gamma_N and at kinks (``contact.ends = "consistent"``).
"""

from __future__ import annotations

import time

import scipy.linalg as sla

from ...forms import Spaces, assemble
from ...mesh import build_mesh
from ...scene import load_scene
from ...verification.infsup import dense_singular_values, gram_matrix, half_norm
from .measure import header

DEFAULT_SCENES = ("thesis-3.46-frictionless", "hertz-cylinder", "flat-punch", "wedge")
# the table ngdual bench infsup prints: (title, key of a record, format)
COLUMNS = (("scene", "scene", "28s"), ("ends", "ends", "10s"), ("level", "level", "5d"),
           ("mult", "multipliers", "6d"), ("X_h", "stresses", "8d"), ("beta_h", "beta", "8.4f"))


def infsup(scene, level: int) -> dict:
    """beta_h of the boundary multipliers of ``scene`` on ``level``."""
    start = time.perf_counter()
    problem = assemble(scene, build_mesh(scene.geometry, level))
    spaces: Spaces = problem.spaces
    norms, names = [], []
    if spaces.neumann is not None:
        n = half_norm(*spaces.neumann.p1_mass_stiffness())
        norms += [n, n]
        names += ["phi1", "phi2"]
    if spaces.contact is not None:
        n = half_norm(*spaces.contact.p1_mass_stiffness())
        norms += [n, n]
        names += ["lam_t", "lam_n"]
    B = problem.block(problem.sigma, problem.index(*names)).toarray()
    A = gram_matrix(problem)[problem.sigma][:, problem.sigma]
    beta = dense_singular_values(A, B, sla.block_diag(*norms))[0]
    return {"scene": scene.name, "ends": scene.contact.ends, "level": level,
            "multipliers": int(B.shape[1]), "stresses": int(A.shape[0]),
            "beta": beta, "seconds": time.perf_counter() - start}


def run(scenes=DEFAULT_SCENES, levels=(1, 2, 3, 4, 5), overrides=(), on_record=None) -> dict:
    """beta_h of every scene of ``scenes`` (with ``overrides``) on every level of ``levels``;
    ``on_record(study)`` after each record."""
    study = header("infsup", scenes=list(scenes), overrides=list(overrides))
    for name in scenes:
        scene = load_scene(name, list(overrides))
        for level in levels:
            study["records"].append(infsup(scene, level))
            if on_record:
                on_record(study)
    return study
