# %% [markdown]
# # Tutorial 3: Signorini contact and the Uzawa algorithm
#
# **Run time** on a 2-core laptop: about 2 min; about 7 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 03 --quick`).
#
# **The idea in words.** A body pressed onto a rigid foundation may touch it but not
# pass through it, and the foundation can only push, never pull. So at every point of
# the contact boundary either the gap is open and the contact pressure is zero, or the
# gap is closed and the pressure is positive; which points are which is part of the
# answer. In the stress-based method the remaining gap is a Lagrange multiplier that must
# stay non-negative. The Uzawa algorithm finds it by repetition: guess the gap, solve a
# linear elasticity problem with it, see where the body would penetrate or pull, correct
# the guess and push it back into the allowed set (a projection), until nothing changes.
# The pictures below show the block, its contact pressure, and how fast the iteration
# settles for different step lengths and ways of measuring the correction.
#
# **Problem.** Example 3.46 of the thesis without friction (with consistent ends of
# $\Gamma_C$, see below): the block
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
# Algorithm 3.38 (Uzawa): one linear saddle-point solve with a fixed matrix per step, then
# a projection $P^+$ of $\lambda_n$ onto the cone $\lambda_n \ge 0$ in a metric $W$: why
# $P^+$ is a small QP and not componentwise clipping (Remark 3.40), how the step length
# $\rho$ and the metric set the number of iterations, and that the result is the one
# convex QP of the whole problem.
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011: Section 3.3, eqs.
# (3.98)-(3.107), Algorithm 3.38, Theorem 3.39, Remark 3.40, Example 3.46, Table 3.5.
# M. Maischak, *FEM/BEM methods for Signorini-type problems* (Habilitation, Hannover
# 2004), Section 5.3.

# %% [markdown]
# ## Parameters
# The algorithms themselves are the subject here: `nd.assemble` builds the matrices,
# `nd.solvers` holds the thesis' algorithms one by one (`nd.solvers.uzawa` for
# Algorithm 3.38, `nd.solvers.projections` for its projection, `nd.solvers.qp` the
# reference QP solver, `nd.solvers.linear` the linear solve).

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

uzawa = nd.solvers.uzawa.uzawa                            # Algorithm 3.38
UzawaSettings = nd.solvers.UzawaSettings                  # its step length, metric, tolerance
Model = nd.solvers.Model                                  # the law and moduli the QPs need
metric_matrix = nd.solvers.projections.metric_matrix      # the metric W of the projection
NonnegativeProjection = nd.solvers.projections.NonnegativeProjection  # P+ onto lambda_n >= 0
solve_qp = nd.solvers.qp.solve_qp                         # the whole problem as one convex QP

lesson = nd.Lesson("03_signorini_uzawa")                    # figures and results.json go here
QUICK = lesson.quick
STRESS = ("r1", "r2", "b1", "b2")   # the stress unknowns: two RT0 rows, two Curl bubbles
LEVEL = 2 if QUICK else 4                                # mesh level of Example 3.46
RHOS = [0.25, 0.5, 1.0, 1.5]                             # step lengths of Algorithm 3.38
TOO_LARGE_RHO = 3.0                                      # beyond the convergence range
MAX_ITER = 500                                           # per run of the sweep
SHORT_RUN = 40                                           # iterations shown for TOO_LARGE_RHO
METRICS = ["h12", "euclidean"]
REFINEMENT_LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4, 5]
EPS = 1e-8                                               # stopping tolerance (step 5)
EPS_COMPARE = 1e-10                                      # tighter, for the comparison with the QP

# %% [markdown]
# ## The scene and the answer
#
# $\Gamma_D$ the clamped ends, $\Gamma_N$ the top with the parabolic traction, $\Gamma_C$
# the bottom above the foundation. `nd.solve` gives the answer this tutorial takes apart:
# $p_h = -\sigma_n \ge 0$ where the gap $\lambda_n$ has closed, zero where it is open.
#
# Where $\Gamma_C$ meets the clamped ends, the body cannot move ($u = 0$) while the
# foundation is $g = 0.01$ away. The thesis' own setting (`contact.ends = "thesis"`, kept
# in the shipped scene to reproduce its tables) still asks the gap multiplier to vanish
# there, i.e. $u_n = g$ against $u = 0$: the stress is then not square integrable at the
# two corners, and `nd.solve` warns about tension and force balance on $\Gamma_C$. We use
# `contact.ends = "consistent"`, the default of every other scene, which leaves the
# multiplier free at the clamped ends: the same problem away from the corners, and a
# solve without warnings.

# %%
scene = nd.load_scene("thesis-3.46-frictionless", ["contact.ends='consistent'"])
lesson.save(nd.plot_geometry(scene, level=LEVEL), "geometry")
lesson.save(nd.plot_contact_traces(nd.contact_traces(nd.solve(scene, LEVEL)),
                                   f"Example 3.46 without friction, level {LEVEL}"),
            "contact_traces")

# %% [markdown]
# ## 1. The algebraic problem
#
# `assemble` builds the matrix of (3.103) once. The unknown vector is ordered
# $[\sigma \mid u, \eta, \varphi, \lambda_t \mid \lambda_n]$; `problem.sigma`,
# `problem.mult` and `problem.lam_n` index the three groups, and
# `problem.block(rows, cols)` cuts out $A$, $B$ and $C_n$.

# %%
problem = nd.assemble(scene, nd.build_mesh(scene.geometry, LEVEL))
A = problem.block(problem.sigma, problem.sigma)
B = problem.block(problem.sigma, problem.mult)
C_n = problem.block(problem.sigma, problem.lam_n)
print(f"dofs (Table 3.1): {problem.spaces.dofs()}; A {A.shape}, B {B.shape}, C_n {C_n.shape}")

# %% [markdown]
# ## 2. One Uzawa step by hand, and the projection $P^+$ as a QP
#
# Algorithm 3.38 starts from $\lambda_n^0 = 0$. Step 3 then solves the saddle-point system
# without contact forces: the body falls through the foundation.
# `nd.solvers.linear.solve_linear` does exactly this solve. The vector $C_n^\top\sigma^1$
# tests $\sigma_n$ with the coarse hat functions; positive entries are where the contact
# condition is violated.

# %%
first = nd.solvers.linear.solve_linear(problem)
traction = C_n.T @ first.part(*STRESS)
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
# so $\Phi$ never has to be computed. $W$ is the discrete $H^{1/2}(\Gamma_C)$ metric
# `metric_matrix(..., "h12")`: dense, not diagonal. `NonnegativeProjection(W)` solves the
# QP as a non-negative least-squares problem (an active-set method, as used by `uzawa`);
# with `solver="cvxpy"` it hands the same QP to the interior-point solver Clarabel instead,
# an independent check.

# %%
rho = 1.0
W = metric_matrix(problem.spaces.contact, scene.material.plane_strain_modulus, "h12")
lam0 = np.zeros(len(problem.lam_n))
c = W @ lam0 + rho * traction

lam1_clarabel = NonnegativeProjection(W, solver="cvxpy")(c)  # interior point (Clarabel)
lam1_nnls = NonnegativeProjection(W)(c)                   # active set, as used by `uzawa`
clipped = np.maximum(np.linalg.solve(W, c), 0.0)          # componentwise clipping of W⁻¹c
gradient = W @ lam1_nnls - c                              # KKT: >= 0, and 0 where λ > 0
projection_check = {
    "cvxpy_vs_ngdual": float(np.linalg.norm(lam1_clarabel - lam1_nnls)
                             / np.linalg.norm(lam1_nnls)),
    "kkt_gradient_min": float(gradient.min() / np.max(np.abs(c))),
    "kkt_complementarity": float(abs(lam1_nnls @ gradient)
                                 / (np.linalg.norm(lam1_nnls) * np.linalg.norm(c))),
    "clipping_differs_by": float(np.linalg.norm(clipped - lam1_nnls)
                                 / np.linalg.norm(lam1_nnls)),
}
for key, value in projection_check.items():
    print(f"{key:22s} {value: .2e}")

# %% [markdown]
# The two solvers agree (an interior-point solver stops at a tolerance; ngdual then
# re-solves exactly on the active set it finds), and the KKT conditions of the QP
# ($W\lambda - c \ge 0$, complementary to $\lambda \ge 0$) hold.
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
# Too large a step and the iteration no longer contracts: with $\rho = 3$ the increments
# stop decreasing (Theorem 3.39: a contraction only for $\rho$ below a bound set by the
# ellipticity of $\tilde a$, about 2 in ngdual's scaling). `converged` says so; ngdual
# never passes an unconverged iterate off as a solution.

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
lesson.save(fig, "uzawa_histories")

# %% [markdown]
# ## 4. Iterations under refinement (Remark 3.40)
#
# The proof works in $H^{1/2}(\Gamma_C)$ and carries over to any metric $W$ *equivalent*
# to it with constants independent of $h$, such as `"h12"` (a discrete $H^{1/2}_{00}$
# norm): then the iteration count does not grow. The Euclidean metric's constants degrade
# like $1/h$, and so does the count.

# %%
by_level = {metric: [] for metric in METRICS}
for level in REFINEMENT_LEVELS:
    refined = nd.assemble(scene, nd.build_mesh(scene.geometry, level))
    for metric in METRICS:
        by_level[metric].append(uzawa(refined, UzawaSettings.from_scene(scene, rho=1.0, eps=EPS,
                                                                        metric=metric))
                                .iterations["outer"])
    print(f"level {level}: iterations h12 {by_level['h12'][-1]:4d}, "
          f"euclidean {by_level['euclidean'][-1]:4d}")

fig, ax = plt.subplots(figsize=(6, 4))
for metric in METRICS:
    ax.plot(REFINEMENT_LEVELS, by_level[metric], "o-", label=f"metric {metric!r}")
ax.set(xlabel="level (h halves per level)", ylabel="Uzawa iterations, ρ = 1",
       xticks=REFINEMENT_LEVELS)
ax.grid(True, alpha=0.3)
ax.legend()
lesson.save(fig, "iterations_per_level")

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


def relative(a, b):
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


agreement = {"sigma": relative(tight.part(*STRESS), reference.part(*STRESS)),
             "lam_n": relative(tight.part("lam_n"), reference.part("lam_n")),
             "nodes_in_contact": [nd.result_record(s)["contact"]["nodes_in_contact"]
                                  for s in (tight, reference)]}
print(f"Uzawa vs QP: sigma {agreement['sigma']:.1e}, lambda_n {agreement['lam_n']:.1e}, "
      f"nodes in contact {agreement['nodes_in_contact']}")

# %%
lesson.results({
    "level": LEVEL,
    "projection": projection_check,
    "iterations": {metric: {str(rho): runs[(metric, rho)].iterations["outer"] for rho in RHOS}
                   for metric in METRICS},
    "converged": {metric: {str(rho): runs[(metric, rho)].converged for rho in RHOS}
                  for metric in METRICS},
    "overshoot": {"rho": TOO_LARGE_RHO, "converged": overshoot.converged},
    "iterations_per_level": {"levels": REFINEMENT_LEVELS, **by_level},
    "agreement": agreement,
    "residuals": tight.residuals,
})

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
