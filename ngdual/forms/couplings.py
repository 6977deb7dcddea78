"""The forms of (3.62) besides the PEERS block: the couplings d_N, d_C of the boundary
multipliers with sigma, the right-hand side (f, u_D, t0, g), and the known values of the
multipliers (the lift at the fixed ends, the discrete gap) that move to the right-hand side."""

from __future__ import annotations

import ngsolve as ngs
import numpy as np

from .. import peers
from ..contact import curve_normal, gap_coefficient
from ..expr import Expression
from ..geometry import tangent
from ..scene import Scene
from .rules import LOAD_RULES, TRACE_RULES
from .spaces import Spaces, boundary_regex


def traction_coefficient(scene: Scene, mesh: ngs.Mesh) -> ngs.CoefficientFunction:
    """The traction t0 on Gamma_N as one vector coefficient: the formula pair of each
    Gamma_N side on that side (:meth:`~ngdual.scene.Scene.tractions`), zero elsewhere.

    >>> from ngdual.mesh import build_mesh
    >>> from ngdual.scene import load_scene
    >>> scene = load_scene("hertz-cylinder", ['loads.traction={left = ["1", "0"]}'])
    >>> mesh = build_mesh(scene.geometry, 1)
    >>> t0 = traction_coefficient(scene, mesh)
    >>> gamma_n = mesh.Boundaries("left|right")          # the sides are 4 long, right is free
    >>> [round(v, 6) for v in ngs.Integrate(t0, mesh, ngs.BND, definedon=gamma_n)]
    [4.0, 0.0]
    """
    pairs = {label: tuple(both) for label, both in scene.tractions().items()}
    if len(set(pairs.values())) == 1:  # one formula pair on every side: no per-side switch
        return ngs.CF(tuple(Expression(e).coefficient() for e in next(iter(pairs.values()))))
    return mesh.BoundaryCF({label: ngs.CF(tuple(Expression(e).coefficient() for e in both))
                            for label, both in pairs.items()}, default=ngs.CF((0.0, 0.0)))


def coupling_forms(scene: Scene, fes: ngs.FESpace, names: list[str], spaces: Spaces):
    """The forms of (3.62) besides the PEERS block
    (:func:`~ngdual.forms.peers_block.broken_peers`): the couplings d_N, d_C with the
    boundary multipliers (None without Gamma_N and Gamma_C) and the right-hand side.

    The PEERS block is a form of its own, so that the large volume matrix never meets the
    prolongation of the multipliers (:func:`~ngdual.forms.assembly.assemble`).
    """
    mesh = fes.mesh
    trial = dict(zip(names, fes.TrialFunction()))
    test = dict(zip(names, fes.TestFunction()))
    n = ngs.specialcf.normal(2)
    t = tangent(n)
    trac_sig = peers.stress_traction(trial["r1"], trial["r2"])
    trac_tau = peers.stress_traction(test["r1"], test["r2"])
    v = ngs.CF((test["u1"], test["u2"]))
    d = ngs.BilinearForm(fes) if {"phi1", "lam_n"} & set(names) else None
    rhs = ngs.LinearForm(fes)
    f = ngs.CF(tuple(Expression(e).coefficient() for e in scene.loads.body_force))
    rhs += -f * v * ngs.dx(intrules=LOAD_RULES)                               # -f(v)
    ds_d = ngs.ds(definedon=mesh.Boundaries(boundary_regex(scene.labels("dirichlet"))),
                  intrules=TRACE_RULES)
    u_d = ngs.CF(tuple(Expression(e).coefficient() for e in scene.loads.displacement))
    rhs += u_d * trac_tau * ds_d                                              # u = u_D on Gamma_D
    if "phi1" in names:
        ds_n = ngs.ds(definedon=mesh.Boundaries(boundary_regex(scene.labels("neumann"))),
                      intrules=TRACE_RULES)
        phi, psi = ngs.CF((trial["phi1"], trial["phi2"])), ngs.CF((test["phi1"], test["phi2"]))
        d += (phi * trac_tau + psi * trac_sig) * ds_n                         # d_N(phi, tau)
        rhs += traction_coefficient(scene, mesh) * psi * ds_n                 # t0(psi)
    if "lam_n" in names:
        ds_c = ngs.ds(definedon=mesh.Boundaries(boundary_regex(scene.labels("contact"))),
                      intrules=TRACE_RULES)
        if spaces.contact.curve_normal:
            # the normal and tangent of the boundary curve, not of its chords (curve_normal)
            n = curve_normal(scene, mesh)
            t = tangent(n)
        d += (trial["lam_t"] * (t * trac_tau) + test["lam_t"] * (t * trac_sig)) * ds_c  # d_Ct
        d += (trial["lam_n"] * (n * trac_tau) + test["lam_n"] * (n * trac_sig)) * ds_c  # d_Cn
        if scene.contact.discrete_gap == "thesis":
            rhs += gap_coefficient(scene) * (n * trac_tau) * ds_c             # g(tau)
    return d, rhs


def discrete_gap(scene: Scene, spaces: Spaces, fes: ngs.FESpace, names: list[str]
                  ) -> np.ndarray:
    """g_h = I_h~ g in the lambda_n block of the fine unknowns (``contact.discrete_gap =
    "nodal"``; zero for ``"thesis"``, whose g(tau) is the integral of g in :func:`coupling_forms`).

    g(tau) = d_Cn(g_h, tau): the gap enters like a known part of lambda_n, so that
    lambda_n - g_h = -u_n lies in the multiplier space
    (:meth:`ngdual.contact.ContactBoundary.gap_interpolant`).
    """
    gap = np.zeros(fes.ndof)
    if spaces.gamma_c is None or scene.contact.discrete_gap == "thesis":
        return gap
    rng = fes.Range(names.index("lam_n"))
    gap[rng.start:rng.stop] = spaces.gamma_c.gap_interpolant(spaces.prolongations["lam_n"],
                                                             spaces.end_hats["lam_n"])
    return gap


def end_lift(scene: Scene, spaces: Spaces, fes: ngs.FESpace, names: list[str]) -> np.ndarray:
    """The known values at the fixed ends of the coarse P1 spaces, where they have no dofs.

    phi = -u_D where Gamma_N meets Gamma_D; lambda_n = g - u_D.n and lambda_t = -u_D.t
    where Gamma_C meets Gamma_D (zero with ``contact.ends = "thesis"``,
    :meth:`ngdual.contact.ContactBoundary.end_values`).
    """
    values = {}
    if spaces.neumann is not None:
        ends = spaces.neumann.end_points()
        for comp, formula in zip(("phi1", "phi2"), scene.loads.displacement):
            values[comp] = -Expression(formula).numpy(ends[:, 0], ends[:, 1])
    if spaces.gamma_c is not None:
        values["lam_n"], values["lam_t"] = spaces.gamma_c.end_values(scene.loads.displacement)
    lift = np.zeros(fes.ndof)
    for comp, value in values.items():
        rng = fes.Range(names.index(comp))
        lift[rng.start:rng.stop] = spaces.end_hats[comp] @ value
    return lift
