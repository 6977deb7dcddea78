"""The active-set solver (condensation onto Gamma_C, semismooth Newton) reaches the discrete
solution of (3.62) that the thesis' Uzawa algorithms converge to, on every shipped scene.

Reference: Algorithm 3.38 / nested Uzawa (Algorithm 3.41, Remark 3.45) at tight tolerances;
where nested Uzawa stagnates (a Coulomb bound made of round-off on a separated Gamma_C,
h^ = h~ with g = 0 ...) the independent QP solver of :mod:`ngdual.solvers.qp`.
Where h^ = h~ and the contact zone reaches the ends of Gamma_C, nu is not unique
(Lemma 3.29), sigma is: only sigma (and F) are compared there.
"""

from functools import cache

import numpy as np
import pytest
import scipy.sparse as sp

from ngdual import post
from ngdual.afem import refine_towards
from ngdual.forms import assemble
from ngdual.friction import build_friction_forms
from ngdual.mesh import build_mesh
from ngdual.scene import SceneError, load_scene, shipped_scenes
from ngdual.solution import ConvergenceError
from ngdual.solvers import solve_problem, solve_scene
from ngdual.solvers.active_set import active_set_solve
from ngdual.solvers.cholesky import SchurCholesky
from ngdual.solvers.convergence import TOLERANCE
from ngdual.solvers.hybrid import HybridSystem
from ngdual.solvers.qp import solve_qp_friction
from ngdual.solvers.semismooth import EPS, kkt_residuals, semismooth_newton
from ngdual.solvers.settings import ActiveSetSettings, Model, UzawaSettings
from ngdual.solvers.uzawa import uzawa

RTOL = 1e-8
CHECKED = ("stationarity", "equality", "lambda_n_negative", "sigma_n_positive",
           "complementarity", "friction_bound", "slip", "coulomb_bound")
UZAWA = "solver.method=uzawa"
TIGHT = ["solver.eps=1e-11", "solver.eps1=1e-11", "solver.eps2=1e-10"]  # Uzawa only
LEVELS = (1, 2, 3)


def rel(a, b):
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))


@cache
def problem(name, level, *overrides):
    scene = load_scene(name, [*(TIGHT if UZAWA in overrides else []), *overrides])
    pb = assemble(scene, build_mesh(scene.geometry, level))
    pb.level = level
    return pb


@cache
def reference(name, level, *overrides):
    """Uzawa at tight tolerances, or the QP reference where Uzawa does not converge.

    Where Gamma_C does not touch, the Coulomb bound is round-off, on which nested Uzawa
    stagnates and the QP's fixed point on F does not settle: there F = 0 and the Coulomb
    solution is the frictionless one, the reference is then Algorithm 3.38.
    """
    pb = problem(name, level, UZAWA, *overrides)
    scene = pb.scene
    if scene.friction.law == "coulomb" and fast(name, level, *overrides).friction_bound.max() == 0:
        sol = uzawa(pb, UzawaSettings.from_scene(scene, eps=1e-11))
        assert sol.converged
        return sol, "frictionless"
    try:
        sol = solve_problem(pb)
        if sol.converged:
            return sol, "uzawa"
    except ConvergenceError:
        pass
    return solve_qp_friction(pb, Model.of(scene)), "qp"


@cache
def fast(name, level, *overrides):
    return solve_problem(problem(name, level, "solver.method=active-set", *overrides))


def assert_same_solution(sol, ref, unique_nu=True):
    pb = sol.problem
    assert rel(sol.x[pb.sigma], ref.x[ref.problem.sigma]) <= RTOL
    if not pb.scene.has_contact:
        return
    lam = np.concatenate([sol.part("lam_n"), sol.part("lam_t")])
    lam_ref = np.concatenate([ref.part("lam_n"), ref.part("lam_t")])
    # lambda = 0 in full stick and contact (g = 0): measure against the displacements
    u = ref.part("u1", "u2")
    scale = max(np.linalg.norm(lam_ref), np.sqrt(np.mean(u**2) * len(lam)))
    assert np.linalg.norm(lam - lam_ref) <= RTOL * scale
    if sol.friction_bound is None:
        return
    F = sol.friction_bound
    if ref.friction_bound is None:  # frictionless reference: valid only for F = 0
        assert F.max() == 0.0
        return
    F_ref = ref.friction_bound
    assert np.abs(F - F_ref).max() <= RTOL * max(F_ref.max(), 1.0)
    if unique_nu:  # nu is arbitrary where F = 0 (or is round-off: no contact)
        forms = build_friction_forms(pb)
        relevant = forms.per_hat_edge(F) > 1e-3 * max(F.max(), 1e-300)
        assert np.abs(sol.nu - ref.nu)[relevant].max(initial=0.0) <= 1e-6



def coarsest_fast(*values):
    """``values`` as parameters, all but level 1 of Example 3.46 in the slow tier (the
    other scenes meet Uzawa on level 1 in tests/test_contact_reach.py)."""
    return [value if value[-1] == 1 and value[0].startswith("thesis-3.46")
            else pytest.param(*value, marks=pytest.mark.slow) for value in values]


SHIPPED = coarsest_fast(*((name, level) for name in shipped_scenes() for level in LEVELS))


@pytest.mark.parametrize(("name", "level"), SHIPPED)
def test_active_set_reaches_the_uzawa_solution_of_every_shipped_scene(name, level):
    sol = fast(name, level)
    ref, _ = reference(name, level)
    assert sol.converged and sol.method.startswith(("active-set", "linear"))
    assert_same_solution(sol, ref)


@pytest.mark.parametrize(("name", "level"), coarsest_fast(*(
    (name, level) for name in ["thesis-3.46-coulomb-gap0", "thesis-3.46-coulomb-gap-abs",
                               "thesis-3.46-coulomb-gap-3125"] for level in LEVELS)))
def test_hhat_equal_htilde_gives_the_unique_sigma(name, level):
    """h^ = h~: the reference is the QP wherever nested Uzawa stagnates; sigma and F agree."""
    sol = fast(name, level, "contact.hhat_factor=1")
    ref, _ = reference(name, level, "contact.hhat_factor=1")
    assert sol.converged
    assert_same_solution(sol, ref, unique_nu=False)


@pytest.mark.parametrize(("name", "level"), [(n, 3) for n in shipped_scenes()])
def test_every_row_and_condition_of_3_62_holds_to_round_off(name, level):
    """Every residual of (3.62) against the problem's scales within TOLERANCE, the verdict of
    every solver; and far below it where the body is not nearly incompressible (measured on
    level 3: at most 3e-14 for nu <= 0.3, 7e-12 on cattaneo-mindlin, nu = 0.4999). The
    reported round-off level is what the conditioning explains: eps (lambda + 2 mu) / mu
    times a mesh factor."""
    sol = fast(name, level)
    r = sol.residuals
    lam, mu = sol.problem.scene.material.lame
    assert sol.roundoff <= 1e3 * EPS * max((lam + 2 * mu) / mu, 100.0)
    for key in CHECKED:
        assert r.get(key, 0.0) <= TOLERANCE, key
    if sol.problem.scene.material.nu <= 0.3:
        for key in CHECKED:
            assert r.get(key, 0.0) <= 1e-12, key


def test_default_method_is_active_set_and_uzawa_stays_available():
    auto = solve_scene(load_scene("thesis-3.46-coulomb"), 2)
    uzawa = solve_scene(load_scene("thesis-3.46-coulomb", ["solver.method=uzawa"]), 2)
    assert auto.method == "active-set-coulomb"
    assert uzawa.method.startswith("nested-uzawa-coulomb")
    assert post.result_record(auto)["parameters"]["solver"]["method"] == "auto"
    linear = solve_scene(load_scene("thesis-3.46-frictionless", ["boundary.contact=[]",
                                                                 "boundary.dirichlet=[\"left\", "
                                                                 "\"right\", \"bottom\"]"]), 2)
    assert linear.method == "linear"


def test_unknown_solver_method_is_named():
    with pytest.raises(SceneError, match="solver.method"):
        load_scene("thesis-3.46-coulomb", ["solver.method=newton"])


def test_physical_units_scale_exactly_in_the_active_set_method():
    base = fast("thesis-3.46-coulomb", 3)
    scaled = fast("thesis-3.46-coulomb", 3, "material.E=2e11",
                  'loads.traction=["0", "-8e8*ifpos(4 - x*x, 1 - x*x/2 + x**4/16, 0)"]')
    assert scaled.iterations == base.iterations
    pb = base.problem
    assert rel(scaled.x[pb.sigma], 1e6 * base.x[pb.sigma]) <= 1e-9
    assert rel(scaled.x[pb.lam_n], base.x[pb.lam_n]) <= 1e-9


@pytest.mark.parametrize("override", [*(pytest.param(o, marks=pytest.mark.slow) for o in (
    "friction.mu=1.0", "friction.mu=2.0", "material.E=2e11")), "material.nu=0.4999"])
def test_hard_parameters_agree_with_the_reference(override):
    sol = fast("thesis-3.46-coulomb", 3, override)
    ref, _ = reference("thesis-3.46-coulomb", 3, override)
    assert_same_solution(sol, ref)


@pytest.mark.slow
def test_strongly_graded_mesh_agrees_with_the_qp_reference():
    scene = load_scene("thesis-3.46-coulomb", ["solver.method=active-set"])
    mesh, coarse = refine_towards(scene, build_mesh(scene.geometry, 2), (-4.0, 0.0), 6)
    pb = assemble(scene, mesh, coarse)
    sol = active_set_solve(pb, ActiveSetSettings.from_scene(scene))
    ref = solve_qp_friction(pb, Model.of(scene))
    assert rel(sol.x[pb.sigma], ref.x[pb.sigma]) <= 1e-7


def test_hybridisation_reproduces_the_rows_of_the_assembled_system():
    """The thesis' configuration (P1 hats on h~, Tresca-ready lambda_t last): for any contact
    multipliers z, the hybridised solve satisfies the sigma, u, eta, phi rows of K x = F,
    keeps z, and b - G z from the Cholesky factor's Schur complement are the moments
    C^T sigma - r of the lambda rows."""
    pb = problem("thesis-3.46-coulomb", 2)
    hs = HybridSystem(pb, friction=True)
    H, last = hs.H, hs.contact_index
    assert abs(H - H.T).max() <= 1e-14 * abs(H).max()
    chol = SchurCholesky(H, last)
    y = chol.forward(hs.rhs(pb.rhs))
    rng = np.random.default_rng(0)
    z = rng.normal(size=len(last)) * 1e-3
    x = hs.solve(chol, y, pb.rhs, z)
    Kx = pb.K @ x
    rows = np.concatenate([pb.sigma, pb.index("u1", "u2", "eta", "phi1", "phi2")])
    assert np.abs(Kx[rows] - pb.rhs[rows]).max() <= 1e-10 * np.abs(Kx).max()
    contact = np.concatenate([pb.lam_n, pb.index("lam_t")])
    assert np.allclose(x[contact], z, rtol=1e-14, atol=0.0)
    t = chol.reduced_rhs(y) - chol.schur @ z
    moments = (Kx - pb.rhs)[contact]
    assert np.allclose(t, moments, rtol=0, atol=1e-10 * np.abs(moments).max())


@pytest.mark.parametrize("name", ["thesis-3.46-coulomb", "hertz-cylinder"])
def test_peers_block_summed_from_the_element_matrices_is_the_conforming_assembly(name):
    """K's PEERS block, summed from the broken element matrices (E^T K_b E), is the matrix
    NGSolve assembles on the conforming space, bit for bit; and broken coefficients that
    restrict a conforming field give that field back."""
    import ngsolve as ngs

    from ngdual import peers
    from ngdual.forms import peers_form
    from ngdual.sparse import to_scipy

    pb = problem(name, 2)
    spaces = [pb.spaces.components[c] for c in peers.PEERS]
    fes = ngs.FESpace(spaces)
    a = ngs.BilinearForm(fes)
    a += peers_form(dict(zip(peers.PEERS, fes.TrialFunction())),
                    dict(zip(peers.PEERS, fes.TestFunction())), pb.scene.material.lame)
    a.Assemble()
    conforming = to_scipy(a.mat)
    conforming.eliminate_zeros()
    n = fes.ndof
    summed = pb.broken.summed(n)
    summed.eliminate_zeros()
    assert (summed != conforming).nnz == 0
    x = np.random.default_rng(3).normal(size=n)
    assert np.array_equal(pb.broken.to_conforming(x[pb.broken.conforming]), x)


def test_broken_rt_map_holds_on_a_mesh_graded_over_ten_orders_of_magnitude():
    """The conforming RT_0 function of every broken one is found on a mesh refined 36 times
    towards a corner (edge lengths from 0.5 to 1e-11): the test for the one nonzero of a
    row is relative to that row, whose entries scale like 1/|e|."""
    import ngsolve as ngs
    from netgen.geom2d import unit_square

    from ngdual.forms.peers_block import _edge_of_broken

    mesh = ngs.Mesh(unit_square.GenerateMesh(maxh=0.5))
    for _ in range(36):
        for el in mesh.Elements():
            mesh.SetRefinementFlag(el, any(mesh[v].point == (0.0, 0.0) for v in el.vertices))
        mesh.Refine()
    rt = ngs.Compress(ngs.HDiv(mesh, order=0))
    broken = ngs.Compress(ngs.HDiv(mesh, order=0, discontinuous=True))
    edge = _edge_of_broken(rt, broken)
    assert np.array_equal(np.bincount(edge, minlength=rt.ndof)[:rt.ndof] > 0,
                          np.ones(rt.ndof, dtype=bool))


@pytest.mark.parametrize("ordering", ["amd", "metis"])
def test_cholesky_with_chosen_unknowns_last_gives_their_schur_complement(ordering):
    rng = np.random.default_rng(1)
    A = sp.random(200, 200, density=0.03, random_state=2)
    H = (A @ A.T + sp.identity(200)).tocsr()
    last = rng.choice(200, 15, replace=False)
    chol = SchurCholesky(H, last, ordering)
    D = H.toarray()
    rest = np.setdiff1d(np.arange(200), last)
    S = D[np.ix_(last, last)] - D[np.ix_(last, rest)] @ np.linalg.solve(
        D[np.ix_(rest, rest)], D[np.ix_(rest, last)])
    np.testing.assert_allclose(chol.schur, S, atol=1e-12 * np.abs(S).max())
    b = rng.normal(size=200)
    np.testing.assert_allclose(H @ chol.solve(b), b, atol=1e-10)
    y = chol.forward(b)
    x_last = rng.normal(size=15)
    x = chol.solve_with_last(y, x_last)
    np.testing.assert_allclose(x[last], x_last, atol=1e-12)
    np.testing.assert_allclose((H @ x - b)[rest], 0.0, atol=1e-10)
    # t(x_last) = r_I - (H x)_I = reduced_rhs - S x_last
    np.testing.assert_allclose(chol.reduced_rhs(y) - chol.schur @ x_last, (b - H @ x)[last],
                               atol=1e-10)


def _random_contact(n_c, n_a, seed):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(2 * n_c, 2 * n_c))
    G = X @ X.T + 2 * n_c * np.eye(2 * n_c)
    b = rng.normal(size=2 * n_c) * 5
    Q = np.abs(rng.normal(size=(n_a, n_c))) * (rng.random((n_a, n_c)) < 0.4)
    return G, b, Q


@pytest.mark.parametrize("seed", range(5))
def test_semismooth_newton_solves_random_tresca_problems(seed):
    G, b, Q = _random_contact(12, 6, seed)
    sol = semismooth_newton(G, b, 12, Q)
    assert max(kkt_residuals(G, b, Q, sol.lam_n, sol.lam_t, sol.nu).values()) <= 1e-10
    # the primal z is the unique minimiser of 1/2 z^T G z - b^T z + |Q lambda_t|_1, lambda_n >= 0
    z = np.concatenate([sol.lam_n, sol.lam_t])
    energy = 0.5 * z @ G @ z - b @ z + np.abs(Q @ sol.lam_t).sum()
    rng = np.random.default_rng(seed)
    for _ in range(20):
        w = z + 1e-3 * rng.normal(size=z.shape)
        w[:12] = np.maximum(w[:12], 0)
        assert 0.5 * w @ G @ w - b @ w + np.abs(Q @ w[12:]).sum() >= energy - 1e-12


def test_qp_fallback_when_newton_is_cut_short():
    G, b, Q = _random_contact(10, 5, 7)
    exact = semismooth_newton(G, b, 10, Q)
    cut = semismooth_newton(G, b, 10, Q, max_iter=1)
    assert cut.fallback
    np.testing.assert_allclose(np.concatenate([cut.lam_n, cut.lam_t]),
                               np.concatenate([exact.lam_n, exact.lam_t]), atol=1e-9)


def test_dependent_stick_rows_leave_z_unique():
    """Two identical rows of Q_F (nu not unique, as for h^ = h~ at the ends of Gamma_C)."""
    G, b, Q = _random_contact(8, 3, 3)
    Q = np.vstack([Q, Q[:1]])
    sol = semismooth_newton(G, b, 8, Q * 1e3)
    assert max(kkt_residuals(G, b, Q * 1e3, sol.lam_n, sol.lam_t, sol.nu).values()) <= 1e-10


def test_the_solvers_blas_limit_covers_every_blas_the_process_has_loaded():
    """blas_threads() scans the BLAS libraries once (threadpoolctl's scan costs about 1.4 ms,
    twice per solve), after loading cvxopt's own; inside it every BLAS threadpoolctl finds
    now runs BLAS_THREADS threads, and outside it the threads are as before."""
    from threadpoolctl import threadpool_info

    from ngdual.solvers.linear import blas_threads
    from ngdual.tolerances import BLAS_THREADS

    with blas_threads():   # the first call loads what the solvers use
        pass
    before = {pool["filepath"]: pool["num_threads"] for pool in threadpool_info()
              if pool["user_api"] == "blas"}
    with blas_threads():
        inside = {pool["filepath"]: pool["num_threads"] for pool in threadpool_info()
                  if pool["user_api"] == "blas"}
    after = {pool["filepath"]: pool["num_threads"] for pool in threadpool_info()
             if pool["user_api"] == "blas"}
    assert inside and set(inside) == set(before)
    assert all(threads == BLAS_THREADS for threads in inside.values())
    assert after == before
