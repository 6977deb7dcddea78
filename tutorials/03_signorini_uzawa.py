# %% [markdown]
# # Tutorial 3: Signorini contact and the Uzawa algorithm
#
# **Problem.** Example 3.46 of the thesis without friction: the block
# $[-4,4]\times[-1,1]$ is clamped at its ends, pressed down by a parabolic traction on top
# and may touch a rigid foundation at distance $g = 0.01$ below $\Gamma_C$ (the bottom).
# In the dual-dual form the contact conditions become a sign condition on the multiplier
# $\lambda_n = g - u_n$ (the remaining gap): find $\sigma$ and
# $(u, \eta, \varphi, \lambda_t)$ and $\lambda_n \in C^+_{\tilde h}$ with
#
# \begin{equation*}
# \begin{aligned}
# A\sigma + B\,(u, \eta, \varphi, \lambda_t) + C_n\lambda_n &= g, &
# B^\top\sigma &= b, \\
# \lambda_n \ge 0, \quad C_n^\top\sigma &\le 0, &
# \lambda_n^\top C_n^\top\sigma &= 0
# \end{aligned}
# \tag{3.103}
# \end{equation*}
#
# (gap $\ge 0$, $\sigma_n \le 0$, complementarity).
#
# **Discretisation.** PEERS for $(\sigma, u, \eta)$, $P_1$ multipliers $\varphi$ on
# $\Gamma_N$ and $\lambda_t$, $\lambda_n$ on $\Gamma_C$ on the coarser boundary mesh
# $\tilde h = 2h$ (eq. (3.61)).
#
# **What you will learn.**
# 1. Algorithm 3.38 (Uzawa): one linear saddle-point solve with a fixed matrix per step,
#    then a projection of $\lambda_n$ onto the cone $\lambda_n \ge 0$.
# 2. The projection $P^+$ as a small convex quadratic program posed in cvxpy, and why its
#    metric $W$ matters (Remark 3.40): $P^+$ is *not* componentwise clipping.
# 3. How the step length $\rho$ and the metric (`"h12"` vs `"euclidean"`) change the
#    number of iterations, on one mesh and under refinement, and what a too large $\rho$
#    does.
# 4. How to check the result against an independent solver (one convex QP, `solve_qp`).
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011: Section 3.3, eqs.
# (3.98)-(3.107), Algorithm 3.38, Theorem 3.39, Remark 3.40, Example 3.46, Table 3.5.
# M. Maischak, *FEM/BEM methods for Signorini-type problems* (Habilitation, Hannover
# 2004), Section 5.3.

# %% [markdown]
# ## Parameters
# The algorithms themselves are the subject here, so besides the public API
# (`import ngdual as nd`) this tutorial imports the Uzawa loop, its projection and the
# reference QP solver from their modules.

# %%
import cvxpy as cp
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd
from ngdual import peers
from ngdual.forms import assemble
from ngdual.mesh import build_mesh
from ngdual.solvers.linear import solve_linear
from ngdual.solvers.projections import NonnegativeProjection, metric_matrix
from ngdual.solvers.reference import solve_qp
from ngdual.solvers.settings import Model, UzawaSettings
from ngdual.solvers.uzawa import uzawa
from ngdual.studies.tutorials import (
    draw,
    output_dir,
    plot_geometry,
    plot_von_mises,
    quick_mode,
    save_figure,
    save_results,
)

QUICK = quick_mode()
LEVEL = 2 if QUICK else 4                                # mesh level of Example 3.46
RHOS = [0.25, 0.5, 1.0, 1.5]                             # step lengths of Algorithm 3.38
TOO_LARGE_RHO = 3.0                                      # beyond the convergence range
MAX_ITER = 500                                           # per run of the sweep
SHORT_RUN = 40                                           # iterations shown for TOO_LARGE_RHO
METRICS = ["h12", "euclidean"]
REFINEMENT_LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4, 5]
EPS = 1e-8                                               # stopping tolerance (step 5)
EPS_COMPARE = 1e-10                                      # tighter, for the comparison with the QP
OUT = output_dir("03_signorini_uzawa")
print(f"quick mode: {QUICK}; level {LEVEL}; output in {OUT}")

# %% [markdown]
# ## 1. The algebraic problem
#
# The block $[-4,4]\times[-1,1]$: $\Gamma_D$ the clamped ends, $\Gamma_N$ the top with the
# parabolic traction, $\Gamma_C$ the bottom above the foundation.
#
# `assemble` builds the matrix of (3.103) once. The unknown vector is ordered
# $[\sigma \mid u, \eta, \varphi, \lambda_t \mid \lambda_n]$; `problem.sigma`,
# `problem.mult` and `problem.lam_n` index the three groups, and
# `problem.block(rows, cols)` cuts out $A$, $B$ and $C_n$.

# %%
scene = nd.load_scene("thesis-3.46-frictionless")
save_figure(plot_geometry(scene, level=LEVEL,
                          title=f"Example 3.46: boundary parts and mesh, level {LEVEL}"),
            OUT / "geometry.png")
problem = assemble(scene, build_mesh(scene.geometry, LEVEL))
A = problem.block(problem.sigma, problem.sigma)
B = problem.block(problem.sigma, problem.mult)
C_n = problem.block(problem.sigma, problem.lam_n)
print(f"dofs per space (Table 3.1): {problem.spaces.dofs()}")
print(f"A: {A.shape}, B: {B.shape}, C_n: {C_n.shape}")

# %% [markdown]
# ## 2. One Uzawa step by hand, and the projection $P^+$ as a QP
#
# Algorithm 3.38 starts from $\lambda_n^0 = 0$. Step 3 then solves the saddle-point system
# without contact forces: the body falls through the foundation. `solve_linear` does
# exactly this solve. The vector $C_n^\top\sigma^1$ tests $\sigma_n$ with the coarse hat
# functions; positive entries are where the contact condition is violated.

# %%
first = solve_linear(problem)
traction = C_n.T @ first.part(*peers.STRESS)
print(f"C_n^T sigma^1: {np.sum(traction > 0)} of {len(traction)} coarse nodes violate sigma_n <= 0")

# %% [markdown]
# Step 4 sets $\lambda_n^1 = P^+(\lambda_n^0 + \rho\,\Phi(\sigma^1))$, where $\Phi$
# represents $d_{C,n}(\cdot, \sigma)$ in the metric $W$ (3.105) and $P^+$ is the
# $W$-orthogonal projection onto the cone (3.104). Remark 3.40 and (3.106)-(3.107) turn
# this into the convex QP
#
# $$
# \lambda_n^1 = \operatorname*{argmin}_{\chi \ge 0}\ \tfrac12\,\chi^\top W\chi - \chi^\top c,
# \qquad c = W\lambda_n^0 + \rho\, C_n^\top\sigma^1,
# $$
#
# so $\Phi$ never has to be computed. In cvxpy it is four lines. $W$ is the discrete
# $H^{1/2}(\Gamma_C)$ metric `metric_matrix(..., "h12")`: dense, not diagonal.

# %%
rho = 1.0
W = metric_matrix(problem.spaces.contact, scene.material.plane_strain_modulus, "h12")
lam0 = np.zeros(len(problem.lam_n))
c = W @ lam0 + rho * traction

scale = np.max(np.abs(W))                 # O(1) numbers help the interior-point solver
chi = cp.Variable(len(c))
qp = cp.Problem(cp.Minimize(0.5 * cp.quad_form(chi, W / scale) - (c / scale) @ chi), [chi >= 0])
qp.solve(solver=cp.CLARABEL, tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12)
lam1_cvxpy = np.maximum(chi.value, 0.0)

lam1_ngdual = NonnegativeProjection(W)(c)            # the same QP, as used by `uzawa`
clipped = np.maximum(np.linalg.solve(W, c), 0.0)     # componentwise clipping of W⁻¹c
gradient = W @ lam1_ngdual - c                       # KKT: >= 0, and 0 where λ > 0
projection_check = {
    "cvxpy_vs_ngdual": float(np.linalg.norm(lam1_cvxpy - lam1_ngdual)
                             / np.linalg.norm(lam1_ngdual)),
    "kkt_gradient_min": float(gradient.min() / np.max(np.abs(c))),
    "kkt_complementarity": float(abs(lam1_ngdual @ gradient)
                                 / (np.linalg.norm(lam1_ngdual) * np.linalg.norm(c))),
    "clipping_differs_by": float(np.linalg.norm(clipped - lam1_ngdual)
                                 / np.linalg.norm(lam1_ngdual)),
}
for key, value in projection_check.items():
    print(f"{key:22s} {value: .2e}")

# %% [markdown]
# cvxpy and ngdual agree (an interior-point solver stops at a tolerance, hence the tight
# settings; ngdual also re-solves exactly on the active set it finds), and the KKT
# conditions of the QP ($W\lambda - c \ge 0$, complementary to $\lambda \ge 0$) hold.
# Clipping $W^{-1}c$ at zero gives a different vector: in a non-diagonal metric the
# projection couples the nodes. For the diagonal `"euclidean"` metric
# $W = (E^*/2)\,I$ the QP has the closed form $\max(0, c/w)$, which ngdual uses.
#
# ## 3. The step length $\rho$ and the metric
#
# Theorem 3.39: the iteration converges for $0 < \rho < 2\alpha$ ($\alpha$ the ellipticity
# constant of $\tilde a$). ngdual scales $W$ with the plane-strain modulus $E^*$, so
# $\rho$ is dimensionless and values around 1 work for any $E$. `uzawa` returns a
# `Solution` whose `history` holds the relative increment of step 5 for every iteration.

# %%
runs = {}
for metric in METRICS:
    for rho in RHOS:
        solution = uzawa(problem, UzawaSettings.from_scene(scene, rho=rho, eps=EPS, metric=metric,
                                                           max_iter=MAX_ITER))
        runs[(metric, rho)] = solution
        print(f"metric {metric:9s} rho = {rho:4.2f}: {solution.iterations['outer']:4d} "
              f"iterations, converged {solution.converged}")

# %% [markdown]
# For small $\rho$ the contraction factor is about $1 - c\rho$, so halving $\rho$ doubles
# the number of iterations.
#
# Too large a step and the iteration no longer contracts. A short run is enough to see
# it: with $\rho = 3$ the increments stop decreasing after a few steps and the iteration
# oscillates (or diverges, in which case `uzawa` raises `ConvergenceError`). Theorem 3.39
# explains why: $\lambda \mapsto P^+(\lambda + \rho\,\Phi(\sigma(\lambda)))$ is a
# contraction only for $\rho$ below a bound set by the ellipticity of $\tilde a$ (in
# ngdual's scaling about 2; where exactly depends on the mesh: on level 4, $\rho = 2$
# already stalls). ngdual reports this through `converged`; it never passes an
# unconverged iterate off as a solution.

# %%
overshoot = uzawa(problem, UzawaSettings.from_scene(scene, rho=TOO_LARGE_RHO, eps=EPS, metric="h12",
                                                    max_iter=SHORT_RUN))
print(f"rho = {TOO_LARGE_RHO}: converged {overshoot.converged} after "
      f"{overshoot.iterations['outer']} iterations, last increment {overshoot.history[-1]:.1e}")

fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
for ax, metric in zip(axes, METRICS):
    for rho in RHOS:
        history = runs[(metric, rho)].history
        ax.semilogy(range(1, len(history) + 1), history, label=f"ρ = {rho}")
    ax.set_title(f"metric {metric!r}, level {LEVEL}")
    ax.set_xlabel("Uzawa iteration i")
    ax.grid(True, which="both", alpha=0.3)
axes[0].semilogy(range(1, len(overshoot.history) + 1), overshoot.history, "r--",
                 label=f"ρ = {TOO_LARGE_RHO} ({SHORT_RUN} steps)")
axes[0].set_ylabel("relative increment (step 5)")
axes[0].legend()
save_figure(fig, OUT / "uzawa_histories.png")

# %% [markdown]
# ## 4. Iterations under refinement (Remark 3.40)
#
# The convergence proof works in the $H^{1/2}(\Gamma_C)$ inner product and carries over to
# any metric $W$ whose norm is *equivalent* to it; if the equivalence constants do not
# depend on $h$, neither does the contraction factor. The `"h12"` metric (a discrete
# $H^{1/2}_{00}$ interpolation norm) is such a metric. The Euclidean one is not: its
# equivalence constants degrade like $1/h$, and the iteration count grows accordingly.

# %%
by_level = {metric: [] for metric in METRICS}
for level in REFINEMENT_LEVELS:
    refined = assemble(scene, build_mesh(scene.geometry, level))
    for metric in METRICS:
        by_level[metric].append(uzawa(refined, UzawaSettings.from_scene(scene, rho=1.0, eps=EPS,
                                                                        metric=metric))
                                .iterations["outer"])
    print(f"level {level}: iterations h12 {by_level['h12'][-1]:4d}, "
          f"euclidean {by_level['euclidean'][-1]:4d}")

fig, ax = plt.subplots(figsize=(6, 4))
for metric in METRICS:
    ax.plot(REFINEMENT_LEVELS, by_level[metric], "o-", label=f"metric {metric!r}")
ax.set_xlabel("level (h halves per level)")
ax.set_ylabel("Uzawa iterations, ρ = 1")
ax.set_xticks(REFINEMENT_LEVELS)
ax.grid(True, alpha=0.3)
ax.legend()
save_figure(fig, OUT / "iterations_per_level.png")

# %% [markdown]
# ## 5. An independent check: the whole problem as one QP
#
# (3.103) is the KKT system of
#
# $$
# \min_\sigma\ \tfrac12\,\sigma^\top A\sigma - g^\top\sigma
# \quad\text{subject to}\quad B^\top\sigma = b,\quad C_n^\top\sigma \le 0,
# $$
#
# with $\lambda_n$ the multiplier of the inequality. `solve_qp` hands this QP to Clarabel
# through cvxpy and shares nothing with the Uzawa loop but the matrices. Both must agree.

# %%
tight = uzawa(problem, UzawaSettings.from_scene(scene, rho=1.0, eps=EPS_COMPARE, metric="h12"))
reference = solve_qp(problem, Model.of(scene))


def relative_difference(a, b):
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


agreement = {
    "sigma": relative_difference(tight.part(*peers.STRESS), reference.part(*peers.STRESS)),
    "lam_n": relative_difference(tight.part("lam_n"), reference.part("lam_n")),
    "nodes_in_contact": [nd.result_record(s)["contact"]["nodes_in_contact"]
                         for s in (tight, reference)],
}
print(f"Uzawa vs QP: sigma {agreement['sigma']:.1e}, lambda_n {agreement['lam_n']:.1e}, "
      f"nodes in contact {agreement['nodes_in_contact']}")
print("contact residuals of the Uzawa solution:",
      {k: f"{v:.1e}" for k, v in tight.residuals.items()})

# %% [markdown]
# The traces on $\Gamma_C$: $\sigma_n \le 0$ everywhere, and $\lambda_n - g = -u_n$
# reaches $-g$ (gap closed, $\lambda_n = 0$) exactly where $\sigma_n < 0$.

# %%
save_figure(nd.plot_contact_traces(nd.contact_traces(tight),
                                    f"Example 3.46 without friction: traces on Γ_C, level {LEVEL}"),
            OUT / "contact_traces.png")

# %% [markdown]
# The stress in the body: the von Mises stress of the Uzawa solution. The corners where
# the clamped ends meet $\Gamma_C$ are singular (Tutorial 6), so the colour scale is
# clipped at the 97th percentile of the element values (stated on the colour bar). In a
# notebook, NGSolve's webgui adds an interactive view.

# %%
mesh = problem.fes.mesh
sigma_h = nd.fields(tight).sigma
save_figure(plot_von_mises(mesh, sigma_h, scene.material.nu,
                           f"Example 3.46 without friction: von Mises stress, level {LEVEL}"),
            OUT / "von_mises.png")
draw(nd.post.von_mises(sigma_h, scene.material.nu), mesh, "von_mises")

# %%
results = {
    "quick": QUICK, "level": LEVEL,
    "projection": projection_check,
    "iterations": {metric: {str(rho): runs[(metric, rho)].iterations["outer"] for rho in RHOS}
                   for metric in METRICS},
    "converged": {metric: {str(rho): runs[(metric, rho)].converged for rho in RHOS}
                  for metric in METRICS},
    "overshoot": {"rho": TOO_LARGE_RHO, "converged": overshoot.converged},
    "iterations_per_level": {"levels": REFINEMENT_LEVELS, **by_level},
    "agreement": agreement,
    "residuals": tight.residuals,
}
print(f"wrote {save_results('03_signorini_uzawa', results)}")

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/03_signorini_uzawa_solutions.py`.
#
# 1. **Optimal $\rho$.** For levels 1-4 and both metrics find the $\rho \in [0.25, 2.5]$
#    with the fewest iterations (compare Table 3.5 of the thesis). How does
#    $\rho_{\mathrm{opt}}$ move with $h$?
# 2. **An $L^2$ metric.** Pose $P^+$ in the mass-matrix metric
#    $W = (E^*/2)\,M/\tilde h$ (scaled so that it has the units of the others) and run the
#    Uzawa loop with it. Is the mass matrix $H^{1/2}$-equivalent? What do the iteration
#    counts do under refinement?
# 3. **Other gaps.** Solve with $g = |x_1|$ and with $g = 0.005 + 0.002\,x_1^2$
#    (`nd.load_scene(..., ["contact.gap='abs(x)'"])`) on level 3 and compare the number of
#    nodes in contact of the Uzawa and the QP solution. Why does the body not touch the
#    foundation $g = |x_1|$ at all on level 2?
