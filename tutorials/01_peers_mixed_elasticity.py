# %% [markdown]
# # Tutorial 1: Mixed elasticity with PEERS
#
# **Problem.** Plane-strain linear elasticity on a polygon Ω, written for the *stress*
# σ as the primary unknown (thesis Ch. 3.1, Hellinger-Reissner form with weakly imposed
# symmetry): find σ, the displacement u and the rotation η = ½(∂₂u₁ − ∂₁u₂) with
#
#     ã(σ, τ) + b(u, τ) + s(η, τ) = ⟨u_D, τn⟩   for all τ   (C⁻¹σ = ε(u), tested)
#     b(v, σ)                     = −f(v)      for all v   (div σ = −f)
#     s(ξ, σ)                     = 0          for all ξ   (σ is symmetric)
#
# with ã(σ, τ) = ∫ C⁻¹σ : τ, b(v, τ) = ∫ v · div τ and s(ξ, τ) = ∫ ξ (τ₁₂ − τ₂₁)
# (eqs. (3.12), (3.24), (3.32); the first three rows of (3.62)). Here u_D = 0 on the
# whole boundary: no Neumann part, no contact.
#
# **Discretisation.** The PEERS triple of Arnold, Brezzi and Douglas, eq. (3.61):
# X_h = RT₀² ⊕ Curl(cubic bubbles)² for the two rows of σ, M_h = P₀² for u and
# S_h = continuous P₁ for η.
#
# **What you will learn.**
# 1. How many unknowns each PEERS space has, and why (Table 3.1).
# 2. What the discrete inf-sup condition (Lemma 3.28) says, how to *compute* the
#    inf-sup constant β_h on small meshes, and why the Curl bubbles are needed.
# 3. What locking is: a primal P1 displacement method fails as ν → ½, PEERS does not.
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, Hannover 2011, Sections 3.1-3.2, eq. (3.61), Lemma 3.28, Table 3.1.
# D. N. Arnold, F. Brezzi, J. Douglas Jr., *PEERS: a new mixed finite element for plane
# elasticity*, Japan J. Appl. Math. 1 (1984). I. Babuška, M. Suri, *Locking effects in
# the finite element approximation of elasticity problems*, Numer. Math. 62 (1992).
#
# Run as a script (`python tutorials/01_peers_mixed_elasticity.py`) or as a notebook
# (`ngdual tutorials --notebooks DIR`). `NGDUAL_QUICK=1` selects coarse settings.

# %%
import matplotlib.pyplot as plt
import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ngdual import peers, post, quantities
from ngdual.expr import Expression
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.scene import Geometry, Loads, Material, Scene, load_scene, validate
from ngdual.solvers import solve_scene
from ngdual.studies.tutorials import draw, output_dir, quick_mode, save_figure, save_results

# %% [markdown]
# ## Parameters
# Quick mode (`NGDUAL_QUICK=1`) keeps every computation to a few seconds.

# %%
QUICK = quick_mode()
DOF_LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4, 5]     # Table 3.1 rows to reproduce
INF_SUP_LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]       # meshes for the eigenvalue problem
LOCKING_LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]       # refinements of the square mesh
NUS = [0.3, 0.45, 0.49, 0.499, 0.4999]                   # Poisson ratios of the locking sweep
SHEAR_MODULUS = 1.0                                      # μ is kept fixed while ν -> 1/2
MAXH = 0.25                                              # netgen mesh size of level 1
OUT = output_dir("01_peers_mixed_elasticity")
print(f"quick mode: {QUICK}; figures and results.json go to {OUT}")

# %% [markdown]
# ## 1. The PEERS spaces and their degrees of freedom
#
# On a triangulation with V vertices, E edges and T triangles:
#
# * RT₀ has one dof per edge (the normal flux), and each row of σ adds one Curl
#   bubble per triangle, so dim X_h = 2(E + T);
# * dim M_h = 2T (a constant vector per triangle) and dim S_h = V.
#
# The structured mesh of Example 3.46 (`thesis_mesh`) reproduces Table 3.1 of the thesis:
# 180, 64, 27 on level 1, and each uniform refinement multiplies T by four.

# %%
thesis = load_scene("thesis-3.46-frictionless")
dof_rows = []
for level in DOF_LEVELS:
    mesh = build_mesh(thesis.geometry, level)
    spaces = peers.peers_spaces(mesh)
    X = sum(spaces[name].ndof for name in peers.STRESS)
    M = spaces["u1"].ndof + spaces["u2"].ndof
    S = spaces["eta"].ndof
    assert (X, M, S) == (2 * (mesh.nedge + mesh.ne), 2 * mesh.ne, mesh.nv)
    dof_rows.append({"level": level, "X": X, "M": M, "S": S})
    print(f"level {level}:  dim X_h = {X:7d}   dim M_h = {M:7d}   dim S_h = {S:6d}")

# %% [markdown]
# ## 2. The discrete inf-sup condition
#
# Lemma 3.28 (from Arnold-Brezzi-Douglas, Lemma 4.4) states that there is β > 0,
# independent of h, with
#
#     sup_{τ ∈ X_h} [b(v, τ) + s(ξ, τ)] / ‖τ‖_X  ≥  β ‖(v, ξ)‖_{L²}   for all (v, ξ) ∈ M_h × S_h,
#
# where ‖τ‖_X² = ‖τ‖² + ‖div τ‖² is the H(div) norm. With the Gram matrices X (of the
# H(div) inner product on X_h) and Y (of L² on M_h × S_h) and the matrix B of b + s,
# the supremum is attained at τ = X⁻¹By, so the best constant is
#
#     β_h² = min_y (yᵀ Bᵀ X⁻¹ B y) / (yᵀ Y y),
#
# the smallest eigenvalue of the pencil (BᵀX⁻¹B, Y): β_h is the smallest singular value
# of B in these norms. If β_h stays away from zero under refinement the triple is stable.
#
# We take Example 3.46 with Dirichlet conditions on all four sides (no boundary
# multipliers) and read B off the assembled system: its block K[σ, (u, η)] is exactly
# b + s. We find the smallest eigenvalues by shift-invert Lanczos (`eigsh`), solving
# with the saddle-point matrix [[X, B], [Bᵀ, σ₀Y]] so that X⁻¹ never becomes dense.

# %%
clamped = load_scene("thesis-3.46-frictionless",
                     ["boundary.dirichlet=['left', 'right', 'bottom', 'top']",
                      "boundary.neumann=[]", "boundary.contact=[]"])


def to_scipy(matrix) -> sp.csr_matrix:
    """An assembled NGSolve matrix as a SciPy CSR matrix."""
    rows, cols, vals = matrix.COO()
    return sp.csr_matrix((np.asarray(vals), (np.asarray(rows), np.asarray(cols))),
                         shape=(matrix.height, matrix.width))


def gram_matrix(problem) -> sp.csr_matrix:
    """Block-diagonal Gram matrix: H(div) on the stress rows, L² on u and η."""
    trial = dict(zip(problem.names, problem.fes.TrialFunction()))
    test = dict(zip(problem.names, problem.fes.TestFunction()))

    def parts(f):
        return (peers.stress(f["r1"], f["r2"], f["b1"], f["b2"]),
                peers.stress_divergence(f["r1"], f["r2"]), ngs.CF((f["u1"], f["u2"])), f["eta"])

    sigma, div_sigma, u, eta = parts(trial)
    tau, div_tau, v, xi = parts(test)
    form = ngs.BilinearForm(problem.fes)
    form += (ngs.InnerProduct(sigma, tau) + div_sigma * div_tau + u * v + eta * xi) * ngs.dx
    form.Assemble()
    return to_scipy(form.mat)


def smallest_singular_values(X, B, Y, k=3, shift=-1e-6) -> np.ndarray:
    """The k smallest singular values of B from X-norm to Y-norm (sqrt of eigenvalues)."""
    n, m = B.shape
    saddle = spla.splu(sp.bmat([[X, B], [B.T, shift * Y]], format="csc"))
    x_lu = spla.splu(X.tocsc())
    schur = spla.LinearOperator((m, m), matvec=lambda y: B.T @ x_lu.solve(B @ y))
    # (BᵀX⁻¹B − shift·Y)⁻¹ r is the second block of the saddle-point solution with rhs (0, −r)
    inverse = spla.LinearOperator((m, m),
                                  matvec=lambda r: saddle.solve(np.r_[np.zeros(n), -r])[n:])
    values = spla.eigsh(schur, k=k, M=Y, sigma=shift, OPinv=inverse,
                        return_eigenvectors=False)
    return np.sqrt(np.maximum(np.sort(values), 0.0))


inf_sup_rows = []
for level in INF_SUP_LEVELS:
    problem = assemble(clamped, build_mesh(clamped.geometry, level))
    G = gram_matrix(problem)
    stress, rt0, mult = problem.sigma, problem.index("r1", "r2"), problem.mult
    Y = G[mult][:, mult]
    peers_beta = smallest_singular_values(G[stress][:, stress], problem.block(stress, mult), Y)
    bare_beta = smallest_singular_values(G[rt0][:, rt0], problem.block(rt0, mult), Y)
    h = np.sqrt(2.0) * 2.0 ** (1 - level)
    inf_sup_rows.append({"level": level, "h": h, "peers": peers_beta.tolist(),
                         "rt0_only": bare_beta.tolist()})
    print(f"level {level}  h = {h:.4f}   PEERS: beta_h = {peers_beta[0]:.4f}   "
          f"RT0 without bubbles: three smallest = {np.array2string(bare_beta, precision=2)}")

# %% [markdown]
# PEERS keeps β_h ≈ 0.39 on every level: the discrete inf-sup condition holds with a
# constant independent of h. Without the Curl bubbles two singular values are zero
# (spurious (u, η) modes that no stress can "see") and the next one decays like h.
# The bubbles are divergence free, so they do not change b(·,·); they enrich the
# antisymmetric part of τ that s(ξ, τ) tests, which is exactly what the rotation needs.

# %%
fig, ax = plt.subplots(figsize=(6, 4))
hs = [row["h"] for row in inf_sup_rows]
ax.loglog(hs, [row["peers"][0] for row in inf_sup_rows], "o-", label="PEERS: RT₀ + Curl bubbles")
ax.loglog(hs, [row["rt0_only"][2] for row in inf_sup_rows], "s--",
          label="RT₀ alone: 3rd smallest (two are 0)")
ax.set_xlabel("mesh size h")
ax.set_ylabel(r"smallest singular value $\beta_h$")
ax.set_title("Discrete inf-sup constant (Lemma 3.28)")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
save_figure(fig, OUT / "inf_sup.png")

# %% [markdown]
# ## 3. Locking-free as ν → ½
#
# On the unit square with u = 0 on the whole boundary we manufacture a divergence-free
# displacement u = Curl ψ = (∂₂ψ, −∂₁ψ), ψ = p(x) p(y), p(t) = t²(1 − t)².
# Since div u = 0, σ = 2μ ε(u) and f = −div σ = −μ Δu do not depend on λ: the same
# exact solution for every ν when μ is fixed. A robust method must give the same
# errors for ν = 0.3 and ν = 0.4999 (λ/μ ≈ 5000).
#
# The primal competitor is the standard P1 method: find u_h ∈ VectorH1(order=1) with
# ∫ 2μ ε(u_h) : ε(v) + λ div u_h div v = ∫ f · v. As λ → ∞ the term λ div u_h div v
# forces div u_h ≈ 0, which continuous P1 fields can barely satisfy: the method *locks*.
#
# The formulas below are scene expressions in x and y (see `ngdual.expr`).

# %%
P = {"p": "(T**2*(1 - T)**2)", "dp": "(2*T - 6*T**2 + 4*T**3)",
     "d2p": "(2 - 12*T + 12*T**2)", "d3p": "(24*T - 12)"}


def term(first: str, second: str) -> str:
    """The product first(x) * second(y) of derivatives of p."""
    return P[first].replace("T", "x") + "*" + P[second].replace("T", "y")


mu = SHEAR_MODULUS
EXACT_U = [term("p", "dp"), f"-{term('dp', 'p')}"]
shear = f"{mu}*({term('p', 'd2p')} - {term('d2p', 'p')})"
EXACT_SIGMA = [[f"{2 * mu}*{term('dp', 'dp')}", shear], [shear, f"-{2 * mu}*{term('dp', 'dp')}"]]
BODY_FORCE = [f"-{mu}*({term('d2p', 'dp')} + {term('p', 'd3p')})",
              f"{mu}*({term('d3p', 'p')} + {term('dp', 'd2p')})"]
SIDES = ["bottom", "right", "top", "left"]


def cf(formula: str) -> ngs.CoefficientFunction:
    return Expression(formula).coefficient()


u_exact = ngs.CF(tuple(cf(c) for c in EXACT_U))
sigma_exact = ngs.CF(tuple(cf(c) for row in EXACT_SIGMA for c in row), dims=(2, 2))


def square_scene(nu: float) -> Scene:
    """The unit square, clamped everywhere, with E chosen so that μ stays fixed."""
    scene = Scene(name=f"square-nu{nu}",
                  geometry=Geometry(kind="polygon", points=[[0, 0], [1, 0], [1, 1], [0, 1]],
                                    labels=SIDES, maxh=MAXH),
                  boundary={"dirichlet": SIDES},
                  material=Material(E=2 * mu * (1 + nu), nu=nu),
                  loads=Loads(body_force=BODY_FORCE))
    validate(scene)
    return scene


def relative_l2(error, exact, mesh) -> float:
    def norm(c):
        return np.sqrt(ngs.Integrate(ngs.InnerProduct(c, c), mesh, order=10))
    return float(norm(error) / norm(exact))


def solve_p1(mesh, material: Material):
    """Primal P1 displacement method; returns (u_h, σ_h = C ε(u_h))."""
    lam, shear_modulus = material.lame
    space = ngs.VectorH1(mesh, order=1, dirichlet="|".join(SIDES))
    u, v = space.TnT()
    a = ngs.BilinearForm(2 * shear_modulus * ngs.InnerProduct(ngs.Sym(ngs.Grad(u)),
                                                              ngs.Sym(ngs.Grad(v))) * ngs.dx
                         + lam * ngs.div(u) * ngs.div(v) * ngs.dx).Assemble()
    force = ngs.CF(tuple(cf(c) for c in BODY_FORCE))
    rhs = ngs.LinearForm(force * v * ngs.dx(bonus_intorder=4)).Assemble()
    uh = ngs.GridFunction(space)
    uh.vec.data = a.mat.Inverse(space.FreeDofs(), inverse="umfpack") * rhs.vec
    return uh, 2 * shear_modulus * ngs.Sym(ngs.Grad(uh)) + lam * ngs.div(uh) * ngs.Id(2)


def errors(nu: float, level: int) -> dict:
    """Relative L² errors of u and σ for PEERS and P1 on the same mesh."""
    scene = square_scene(nu)
    solution = solve_scene(scene, level)
    mesh = solution.problem.fes.mesh
    f = quantities.fields(solution)
    uh, sigma_h = solve_p1(mesh, scene.material)
    return {"nu": nu, "level": level, "triangles": mesh.ne,
            "peers_u": relative_l2(f.u - u_exact, u_exact, mesh),
            "peers_sigma": relative_l2(f.sigma - sigma_exact, sigma_exact, mesh),
            "p1_u": relative_l2(uh - u_exact, u_exact, mesh),
            "p1_sigma": relative_l2(sigma_h - sigma_exact, sigma_exact, mesh)}


print(f"{'nu':>7} {'PEERS u':>9} {'PEERS σ':>9} {'P1 u':>9} {'P1 σ':>9}   "
      f"(relative L² errors, level {LOCKING_LEVELS[-1]})")
sweep = [errors(nu, LOCKING_LEVELS[-1]) for nu in NUS]
for row in sweep:
    print(f"{row['nu']:7.4f} {row['peers_u']:9.3e} {row['peers_sigma']:9.3e} "
          f"{row['p1_u']:9.3e} {row['p1_sigma']:9.3e}")

# %% [markdown]
# PEERS errors do not move as ν → ½; the P1 errors grow with λ/μ. The ratio of the
# errors at ν = 0.4999 and ν = 0.3 condenses this into one number per method:

# %%
first, last = sweep[0], sweep[-1]
ratios = {key: last[key] / first[key] for key in ("peers_u", "peers_sigma", "p1_u", "p1_sigma")}
for key, value in ratios.items():
    print(f"error(nu = {last['nu']}) / error(nu = {first['nu']}) for {key:11s}: {value:8.2f}")

fig, ax = plt.subplots(figsize=(6, 4))
lam_over_mu = [Material(2 * mu * (1 + nu), nu).lame[0] / mu for nu in NUS]
for key, style, label in (("peers_sigma", "o-", "PEERS σ"), ("peers_u", "o--", "PEERS u"),
                          ("p1_sigma", "s-", "P1 σ"), ("p1_u", "s--", "P1 u")):
    ax.loglog(lam_over_mu, [row[key] for row in sweep], style, label=label)
ax.set_xlabel(r"$\lambda/\mu$")
ax.set_ylabel("relative $L^2$ error")
ax.set_title(f"Locking on the unit square, level {LOCKING_LEVELS[-1]}")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
save_figure(fig, OUT / "locking.png")

# %% [markdown]
# Refining the mesh: PEERS converges at first order (Theorem 3.35) for both ν; P1 at
# ν = 0.4999 is far from its asymptotic regime on these meshes.

# %%
convergence = [errors(nu, level) for nu in (NUS[0], NUS[-1]) for level in LOCKING_LEVELS]
print(f"{'nu':>7} {'level':>5} {'triangles':>9} {'PEERS σ':>9} {'P1 σ':>9}")
for row in convergence:
    print(f"{row['nu']:7.4f} {row['level']:5d} {row['triangles']:9d} "
          f"{row['peers_sigma']:9.3e} {row['p1_sigma']:9.3e}")

# %% [markdown]
# In a notebook, NGSolve's webgui shows the PEERS stress interactively (von Mises,
# ν = 0.4999); as a script this cell draws nothing.

# %%
incompressible = solve_scene(square_scene(NUS[-1]), LOCKING_LEVELS[-1])
draw(post.von_mises(quantities.fields(incompressible).sigma, NUS[-1]),
     incompressible.problem.fes.mesh, "von_mises")

# %%
results = {"quick": QUICK, "dofs": dof_rows, "inf_sup": inf_sup_rows,
           "locking_sweep": sweep, "convergence": convergence, "ratios": ratios}
print(f"wrote {save_results('01_peers_mixed_elasticity', results)}")

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/01_peers_mixed_elasticity_solutions.py`.
#
# 1. **The norm matters.** Recompute the smallest *and* the largest singular value of B
#    with the L² norm instead of the H(div) norm on X_h (drop ‖div τ‖² from the Gram
#    matrix). Which of the two depends on h? Why do Lemma 3.28 and the error analysis
#    work in ‖·‖_X?
# 2. **Higher order does not cure locking by itself.** Replace the P1 method by P2
#    (`VectorH1(order=2)`). Compute the error ratio between ν = 0.4999 and ν = 0.3 for
#    the stress. Is P2 locking-free on these meshes?
# 3. **Counting.** Use Euler's formula V − E + T = 1 to write dim X_h, dim M_h and
#    dim S_h of Table 3.1 as functions of the level k of Example 3.46, and check them
#    against `ngdual dofs thesis-3.46-frictionless --levels 1 2 3 4 5 6 7 8`.
