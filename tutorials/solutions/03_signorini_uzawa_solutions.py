# %% [markdown]
# # Solutions to Tutorial 3: Signorini contact and the Uzawa algorithm
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

uzawa = nd.solvers.uzawa.uzawa                            # Algorithm 3.38
UzawaSettings = nd.solvers.UzawaSettings                  # its step length, metric, tolerance
Model = nd.solvers.Model                                  # the law and moduli the QPs need
metric_matrix = nd.solvers.projections.metric_matrix      # the metric W of the projection
NonnegativeProjection = nd.solvers.projections.NonnegativeProjection  # P+ onto lambda_n >= 0
Factorization = nd.solvers.linear.Factorization           # sparse LU factors, solved many times
solve_qp = nd.solvers.qp.solve_qp                         # the whole problem as one convex QP

lesson = nd.Lesson("03_signorini_uzawa_solutions")
QUICK = lesson.quick
LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]
RHOS = [0.5, 1.0, 1.5, 2.0] if QUICK else list(np.arange(0.25, 2.51, 0.25))
scene = nd.load_scene("thesis-3.46-frictionless")
problems = {level: nd.assemble(scene, nd.build_mesh(scene.geometry, level)) for level in LEVELS}

# %% [markdown]
# ## Exercise 1: the optimal step length
#
# With the $H^{1/2}$ metric $\rho_{\mathrm{opt}}$ stays near 1-1.5 on every level: the
# metric already carries the right scaling. With the Euclidean metric the best $\rho$ is
# similar, but the iteration count at $\rho_{\mathrm{opt}}$ grows with the level, as the
# tutorial showed for $\rho = 1$.

# %%
optimal, sweeps = {}, {}
for metric in ("h12", "euclidean"):
    for level, problem in problems.items():
        counts = {}
        for rho in RHOS:
            solution = uzawa(problem, UzawaSettings.from_scene(
                scene, rho=float(rho), eps=1e-8, metric=metric, max_iter=500))
            counts[float(rho)] = solution.iterations["outer"] if solution.converged else np.inf
        best = min(counts, key=counts.get)
        sweeps[(metric, level)] = counts
        optimal[f"{metric}-{level}"] = {"rho": best, "iterations": int(counts[best])}
        print(f"{metric:9s} level {level}: rho_opt = {best:.2f} with {counts[best]} iterations")

# %%
fig, ax = plt.subplots(figsize=(7, 4.5))
for (metric, level), counts in sweeps.items():
    ax.plot(list(counts), list(counts.values()), "o-" if metric == "h12" else "s--",
            label=f"{metric}, level {level}")
ax.set_xlabel(r"step length $\rho$")
ax.set_ylabel("Uzawa iterations to $\\varepsilon = 10^{-8}$")
ax.set_title("Exercise 1: iterations against $\\rho$ (missing point: no convergence)")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
lesson.save(fig, "optimal_rho")

# %% [markdown]
# ## Exercise 2: the mass-matrix ($L^2$) metric
#
# The $L^2$ norm on $\Gamma_C$ is weaker than the $H^{1/2}$ norm by a factor that grows
# like $\tilde h^{-1/2}$ on rough functions: not equivalent uniformly in $h$. Scaling the
# mass matrix by $1/\tilde h$ gives it the units of the other metrics; then, like the
# Euclidean metric, it needs more and more iterations as the mesh is refined, while
# `h12` does not.
#
# Algorithm 3.38 itself fits in a few lines: factorise
# $\begin{pmatrix} A & B \\ B^\top & 0 \end{pmatrix}$ once, then alternate the solve
# (step 3) and the projection in the metric $W$ (step 4).


# %%
def uzawa_by_hand(problem, W, rho=1.0, eps=1e-8, max_iter=2000):
    """Algorithm 3.38 with the projection P+ in the metric W; returns (iterations, converged)."""
    saddle = problem.saddle
    lu = Factorization(problem.block(saddle, saddle))
    C_n = problem.block(problem.sigma, problem.lam_n)
    n_sigma = len(problem.sigma)
    project = NonnegativeProjection(W)
    lam = np.zeros(C_n.shape[1])
    y_old = np.zeros(len(saddle))
    for iteration in range(1, max_iter + 1):
        rhs = problem.rhs[saddle].copy()
        rhs[:n_sigma] -= C_n @ lam
        y = lu.solve(rhs)                                               # step 3
        lam_new = project(W @ lam + rho * (C_n.T @ y[:n_sigma]))        # step 4
        change = np.sqrt(np.sum((y - y_old) ** 2) + np.sum((lam_new - lam) ** 2))
        if change <= eps * np.sqrt(np.sum(y**2) + np.sum(lam_new**2)):  # step 5
            return iteration, True
        y_old, lam = y, lam_new
    return max_iter, False


mass_iterations, hand_vs_ngdual = [], []
for level, problem in problems.items():
    contact = problem.spaces.contact
    mass, _ = contact.p1_mass_stiffness()
    modulus = problem.scene.material.plane_strain_modulus
    its, converged = uzawa_by_hand(problem, modulus / 2 * mass / contact.edge_lengths().mean())
    check, _ = uzawa_by_hand(problem, metric_matrix(contact, modulus, "h12"))
    h12 = uzawa(problem, UzawaSettings.from_scene(scene, rho=1.0, eps=1e-8, metric="h12")
                ).iterations["outer"]
    mass_iterations.append(its)
    hand_vs_ngdual.append((check, h12))
    print(f"level {level}: mass metric {its} iterations (converged {converged}); h12 {h12} "
          f"with ngdual's uzawa, {check} by hand")

# %%
fig, ax = plt.subplots(figsize=(6.5, 4.2))
ax.plot(LEVELS, mass_iterations, "s--", label=r"mass metric $W = (E^*/2)\,M/\tilde h$")
ax.plot(LEVELS, [h12 for _, h12 in hand_vs_ngdual], "o-", label=r"$H^{1/2}$ metric (h12)")
ax.set_xticks(LEVELS)
ax.set_xlabel("mesh level (h halves per level)")
ax.set_ylabel(r"Uzawa iterations, $\rho = 1$")
ax.set_title("Exercise 2: only the $H^{1/2}$ metric keeps the count fixed")
ax.grid(True, alpha=0.3)
ax.legend()
lesson.save(fig, "metrics_under_refinement")

# %% [markdown]
# ## Exercise 3: other gaps
#
# The Uzawa iteration and the independent QP find the same contact nodes. With
# $g = |x_1|$ the body can touch only around $x_1 = 0$. On coarse meshes it does not
# touch at all: $\lambda_n$ is tested with the coarse hats, so the *discrete* gap at the
# node $x_1 = 0$ is a hat-weighted mean of $|x_1|$, about $\tilde h/3$, larger than the
# deflection until $\tilde h$ is small.

# %%
gaps = {}
for gap in ("abs(x)", "0.005 + 0.002*x*x"):
    variant = nd.load_scene("thesis-3.46-frictionless", [f"contact.gap='{gap}'"])
    problem = nd.assemble(variant, nd.build_mesh(variant.geometry, 3 if QUICK else 4))
    nodes = [nd.post.contact_summary(s)["nodes_in_contact"]
             for s in (uzawa(problem, UzawaSettings.from_scene(variant, eps=1e-10)),
                       solve_qp(problem, Model.of(variant)))]
    gaps[gap] = nodes
    print(f"g = {gap:18s}: nodes in contact, Uzawa {nodes[0]}, QP {nodes[1]}")

# %%
lesson.results({"optimal": optimal, "mass_metric_iterations": mass_iterations,
                "hand_vs_ngdual": hand_vs_ngdual, "gaps": gaps})
