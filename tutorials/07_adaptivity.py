# %% [markdown]
# # Tutorial 7: Adaptive refinement
#
# **Problem.** Solutions of contact problems are not smooth: $\sigma$ is singular at
# corners where boundary conditions change, and at the ends of the contact zone. Uniform
# refinement then converges slowly. The indicators $\eta_{tot,T}$ of (4.50) (Tutorial 6)
# say *where* the error is made; refining there should restore the convergence rate that
# PEERS has for smooth solutions, $e \sim N^{-1/2}$ in the number $N$ of unknowns.
#
# **Discretisation.** PEERS (3.61) on netgen meshes refined by bisection with conforming
# closure; the coarse boundary meshes $\tilde h$ ($\Gamma_N$, $\Gamma_C$) and $\hat h$
# ($\nu$) follow the refinement, nested, with $\tilde h \approx 2h$ locally. Each step
# solves the discrete problem (3.62) with the solver the scene asks for
# (`solver.method`; Tutorials 3 and 4 show that they all agree).
#
# **What you will learn.**
# 1. The loop SOLVE → ESTIMATE → MARK → REFINE (`ngdual.afem.adapt`) and its history.
# 2. Three marking strategies (`ngdual.marking`): the maximum strategy and the
#    fixed-fraction strategy of Section 4.2, and Dörfler's bulk criterion.
# 3. On an L-shaped domain with a re-entrant corner (exact solution known): uniform
#    refinement converges like $N^{-\alpha/2}$, $\alpha \approx 0.54$, adaptive refinement
#    like $N^{-1/2}$; rates with `ngdual.rates.fitted_rate` (the order in
#    $h_N = N^{-1/2}$: $e \sim N^{-\mathrm{rate}/2}$).
# 4. Example 3.46 with Coulomb friction: where the indicators refine (Figs. 4.1-4.13),
#    and the total error (3.124) against extrapolated norms (Table 4.4).
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011:
# Section 4.2: Figs. 4.1-4.13, Tables 4.1, 4.3, 4.4;
# eq. (3.124) and Aitken extrapolation in Section 3.4. W. Dörfler, *A convergent adaptive
# algorithm for Poisson's equation*, SIAM J. Numer. Anal. 33 (1996). M. L. Williams,
# *Stress singularities resulting from various boundary conditions in angular corners of
# plates in extension*, J. Appl. Mech. 19 (1952). L. Chen, *iFEM: an innovative finite
# element method package in MATLAB* (2008), the SOLVE-ESTIMATE-MARK-REFINE loop.

# %% [markdown]
# ## Parameters
#
# A run is (marking, $\theta$, number of SOLVE steps). Uniform refinement is `max` with
# $\theta = 0$ (every element has $\eta_T \ge 0 \cdot \max\eta$).

# %%
import math

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import ngsolve as ngs
import numpy as np

import ngdual as nd
from ngdual.afem import reference_norms
from ngdual.marking import STRATEGIES
from ngdual.rates import fitted_rate
from ngdual.studies.tutorials import (
    output_dir,
    plot_geometry,
    quick_mode,
    save_figure,
    save_results,
)
from ngdual.verification import corner

QUICK = quick_mode()
L_RUNS = {"uniform": ("max", 0.0, 3 if QUICK else 5),
          "max": ("max", 0.5, 4 if QUICK else 10),
          "fraction": ("fraction", 0.2, 4 if QUICK else 9),
          "dorfler": ("dorfler", 0.5, 6 if QUICK else 11)}
THESIS_RUNS = {"max": ("max", 0.5, 1, 3 if QUICK else 8),          # Table 4.1: from level 1
               "fraction": ("fraction", 0.2, 2, 3 if QUICK else 5),  # Tables 4.3, 4.4
               "dorfler": ("dorfler", 0.5, 2, 3 if QUICK else 6)}
REFERENCE_LEVELS = [1, 2, 3] if QUICK else [2, 3, 4]   # Aitken extrapolation (Section 3.4)
OUT = output_dir("07_adaptivity")
print(f"quick mode: {QUICK}; output in {OUT}")

# %% [markdown]
# ## 1. Marking is a pure function of the indicators
#
# Given $\eta_T \ge 0$ and $\theta \in [0, 1]$:
#
# * **max** (Section 4.2, first algorithm): refine $T$ if $\eta_T \ge \theta\max_{T'}\eta_{T'}$;
# * **fraction** (Section 4.2, second algorithm): refine the $\lceil\theta N_T\rceil$
#   elements with the largest $\eta_T$;
# * **Dörfler**: refine a smallest set $\mathcal{M}$ with
#   $\sum_{T\in\mathcal{M}} \eta_T^2 \ge \theta\sum_T \eta_T^2$, the *bulk* of the error.
#
# Only Dörfler controls how much of $\eta^2$ is refined; it is the strategy for which
# optimal convergence rates are proven. On the indicators of Example 3.46 (level 2):

# %%
thesis = nd.load_scene("thesis-3.46-coulomb")
save_figure(plot_geometry(thesis, level=2, title="Example 3.46, Coulomb friction: "
                          "boundary parts, level 2"), OUT / "geometry.png")
example = nd.estimate(nd.solve(thesis, 2))
eta = example.eta
examples = {"max": 0.5, "fraction": 0.2, "dorfler": 0.5}
marked_sets = {}
for strategy, theta in examples.items():
    marked_sets[strategy] = nd.mark(eta, theta, strategy)
    chosen = marked_sets[strategy]
    print(f"{strategy:8s} theta = {theta}: {chosen.sum():3d} of {len(eta)} elements, "
          f"{100 * np.sum(eta[chosen] ** 2) / np.sum(eta**2):5.1f} % of eta^2")
assert set(examples) == set(STRATEGIES)


# %%
def triangulation(mesh: ngs.Mesh) -> mtri.Triangulation:
    points = np.array([v.point for v in mesh.vertices])
    triangles = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngs.VOL)])
    return mtri.Triangulation(points[:, 0], points[:, 1], triangles)


def plot_meshes(panels: list, path, title: str, columns: int = 2) -> None:
    """Meshes side by side; ``panels`` holds (triangulation, marked or None, caption)."""
    rows = math.ceil(len(panels) / columns)
    tri0 = panels[0][0]
    aspect = np.ptp(tri0.y) / np.ptp(tri0.x)
    fig, axes = plt.subplots(rows, columns, figsize=(5.5 * columns, 5.5 * rows * aspect + 0.8),
                             squeeze=False)
    for ax, (tri, marked, caption) in zip(axes.flat, panels):
        if marked is not None and np.any(marked):
            ax.tripcolor(tri, facecolors=np.ma.masked_equal(np.asarray(marked, float), 0),
                         cmap="Oranges", vmin=0, vmax=1.5, edgecolors="none")
        ax.triplot(tri, color="k", lw=0.25)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(caption, fontsize=9)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    fig.suptitle(title)
    fig.tight_layout()
    save_figure(fig, path)


level2 = triangulation(nd.solve(thesis, 2).problem.fes.mesh)
plot_meshes([(level2, marked_sets[s], f"{s}, theta = {examples[s]}: {marked_sets[s].sum()} marked")
             for s in examples], OUT / "marking_example.png",
            "Marked elements (shaded), Example 3.46, level 2", columns=1)

# %% [markdown]
# ## 2. The loop
#
# `adapt(scene, marking, theta, steps, level)` runs
#
#     for step in range(steps):
#         SOLVE     solve_problem(assemble(scene, mesh, coarse))
#         ESTIMATE  estimate(solution)                 # eta_T of (4.50), every term
#         MARK      mark(eta_T, theta, marking)
#         REFINE    mesh = refine(mesh, marked); coarse = coarse.follow(scene, mesh)
#
# and returns one record per step: DOFs, $\eta$ and its terms, the norms of Tables
# 3.2/3.3, timings, and with `reference` norms the total error (3.124). An `on_step`
# callback sees the solution, the estimate and the marks of every step (here: to store
# meshes and to compute exact errors).
#
# ## 3. The L-shaped domain: a re-entrant corner
#
# The L-shape $(-1,1)^2$ without the quarter $(0,1)\times(-1,0)$, traction free on the two
# sides at the re-entrant corner, $u = u_{\mathrm{exact}}$ on the others. Near a corner
# of interior angle $2\omega = 3\pi/2$ with free sides, the symmetric (mode I) solution of
# Williams is $u \sim r^\alpha g(\theta)$, $\sigma \sim r^{\alpha-1}$, with
# $\alpha \in (0, 1)$ the root of
#
# $$
# \sin(2\omega\alpha) + \alpha\sin(2\omega) = 0 .
# $$
#
# $\sigma \in H^{\alpha-\varepsilon}$: uniform refinement gives
# $e \sim h^\alpha \sim N^{-\alpha/2}$.

# %%
# The exact solution is in `ngdual.verification.corner` (read its source: Williams'
# formulas written as scene expressions in x and y), with the scene and the exact error of
# PEERS, (‖σ − σ_h‖² + ‖div σ_h‖² + ‖u − u_h‖² + ‖η − η_h‖²)^{1/2}.

# %%
l_shape = corner.l_shape_scene()
alpha = corner.corner_exponent()
print(f"corner exponent alpha = {alpha:.4f}: the uniform rate")
exact = corner.exact_fields()


def exact_error(solution) -> float:
    """The error of PEERS against Williams' corner solution."""
    return corner.exact_error(solution, exact)


# %% [markdown]
# Four runs from the same initial mesh. The callback stores the exact error and the mesh
# of every step.

# %%
def run(scene, marking, theta, steps, level=1, reference=None, error=None) -> dict:
    """adapt(...) with the meshes, marks (and exact errors) of every step kept."""
    kept = {"meshes": [], "errors": []}

    def on_step(record, solution, indicators, marked):
        kept["meshes"].append((triangulation(solution.problem.fes.mesh), marked))
        if error is not None:
            kept["errors"].append(error(solution))

    kept["history"] = nd.adapt(scene, marking, theta, steps, level=level, reference=reference,
                            on_step=on_step)
    return kept


l_runs = {name: run(l_shape, marking, theta, steps, error=exact_error)
          for name, (marking, theta, steps) in L_RUNS.items()}
l_rates = {}
for name, kept in l_runs.items():
    ndofs = [r["dofs"]["total"] for r in kept["history"]]
    etas = [r["estimator"] for r in kept["history"]]
    l_rates[name] = {"error": fitted_rate(ndofs[-3:], kept["errors"][-3:]),
                     "eta": fitted_rate(ndofs[-3:], etas[-3:])}
    print(f"{name:8s}: {len(ndofs)} steps, N = {ndofs[0]} .. {ndofs[-1]}, error "
          f"{kept['errors'][0]:.3e} -> {kept['errors'][-1]:.3e}, eta {etas[0]:.3e} -> "
          f"{etas[-1]:.3e}; rates (last 3 steps): error {l_rates[name]['error']:.3f}, "
          f"eta {l_rates[name]['eta']:.3f}")

# %% [markdown]
# Uniform refinement converges at about the corner exponent $\alpha \approx 0.54$, all
# adaptive strategies at about the optimal rate 1 (the rates from three steps are rough).
# The estimator follows the error: it overestimates it by a factor that stays between
# about 2 and 5.

# %%
fig, ax = plt.subplots(figsize=(7, 5))
for (name, kept), colour in zip(l_runs.items(), ("k", "tab:blue", "tab:orange", "tab:green")):
    ndofs = [r["dofs"]["total"] for r in kept["history"]]
    ax.loglog(ndofs, kept["errors"], "o-", color=colour, label=f"error, {name}")
    ax.loglog(ndofs, [r["estimator"] for r in kept["history"]], "s--", color=colour, ms=4,
              label=f"η, {name}")
n_ref = np.array([l_runs["uniform"]["history"][0]["dofs"]["total"], 2e4])
e_ref = l_runs["uniform"]["errors"][0]
ax.loglog(n_ref, 0.8 * e_ref * (n_ref / n_ref[0]) ** (-alpha / 2), "k:", lw=1,
          label=f"N^(-α/2), α = {alpha:.3f}")
ax.loglog(n_ref, 0.8 * e_ref * (n_ref / n_ref[0]) ** -0.5, "k-.", lw=1, label="N^(-1/2)")
ax.set_xlabel("degrees of freedom N")
ax.set_ylabel("error / estimator")
ax.set_title("L-shape, corner singularity")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7, ncol=2)
save_figure(fig, OUT / "l_shape_convergence.png")

effectivity_l = {name: [r["estimator"] / e for r, e in zip(kept["history"], kept["errors"])]
                 for name, kept in l_runs.items()}
for name, values in effectivity_l.items():
    print(f"{name:8s} effectivity eta/e: [{min(values):.2f}, {max(values):.2f}]")

# %%
dorfler_meshes = l_runs["dorfler"]["meshes"]
plot_meshes([(tri, marked, f"Dörfler step {k}: {tri.triangles.shape[0]} triangles")
             for k, (tri, marked) in enumerate(dorfler_meshes)
             if k in (0, len(dorfler_meshes) // 2, len(dorfler_meshes) - 1)]
            + [(l_runs[name]["meshes"][-1][0], None,
                f"{name}, last step: {l_runs[name]['meshes'][-1][0].triangles.shape[0]} "
                "triangles") for name in ("max", "fraction")],
            OUT / "l_shape_meshes.png", "L-shape: adaptive meshes (shaded: marked)", columns=3)

# %% [markdown]
# ## 4. Example 3.46 with Coulomb friction
#
# The thesis runs the maximum strategy $\theta = 0.5$ from level 1 (Table 4.1,
# Figs. 4.1-4.8) and the fraction strategy $\theta = 0.2$ from level 2 (Tables 4.3-4.4,
# Figs. 4.9-4.13). The exact solution is unknown; as in Section 3.4 the norms of the exact
# solution are extrapolated from uniform levels (Aitken's $\Delta^2$), and $e_{tot}$ of
# (3.124) compares norms:
#
# $$
# e_i(q) = \bigl|\,\|q_h\|^2 - n_q^2\,\bigr|^{1/2} .
# $$
#
# This is a rough error measure: it is blind to errors that do not change the norms.

# %%
reference = reference_norms(thesis, REFERENCE_LEVELS)
thesis_runs = {name: run(thesis, marking, theta, steps, level=level, reference=reference)
               for name, (marking, theta, level, steps) in THESIS_RUNS.items()}
print(f"{'run':9s} {'step':>4} {'elements':>8} {'Dof':>6} {'eta':>10} {'e_tot':>10} "
      f"{'eta/e_tot':>9} {'marked':>6}")
for name, kept in thesis_runs.items():
    for r in kept["history"]:
        print(f"{name:9s} {r['step']:4d} {r['elements']:8d} {r['dofs']['total']:6d} "
              f"{r['estimator']:10.3e} {r['e_tot']:10.3e} {r['effectivity']:9.3f} {r['marked']:6d}")

# %% [markdown]
# $e_{tot}$ jumps up and down from step to step: a difference of norms can be small by
# accident, and the extrapolated norms are themselves uncertain. Its "effectivity index"
# (Table 4.4) inherits that noise, unlike $\eta/e$ on the L-shape with its exact error.
#
# Which terms of (4.50) drive the refinement? The share of each in $\eta^2$ on the last
# step:

# %%
for name, kept in thesis_runs.items():
    terms = kept["history"][-1]["estimator_terms"]
    total = sum(v**2 for v in terms.values())
    leading = sorted(terms, key=lambda k: -terms[k])[:3]
    print(f"{name:9s}: " + ", ".join(f"{k} {100 * terms[k] ** 2 / total:.0f} %" for k in leading))

# %%
panels = []
for name, kept in thesis_runs.items():
    for k in (0, len(kept["meshes"]) - 1):
        tri, marked = kept["meshes"][k]
        panels.append((tri, marked, f"{name}, step {k}: {tri.triangles.shape[0]} triangles"))
plot_meshes(panels, OUT / "thesis_meshes.png",
            "Example 3.46, Coulomb mu_f = 0.5: adaptive meshes (shaded: marked)")

fig, ax = plt.subplots(figsize=(7, 4.5))
for (name, kept), colour in zip(thesis_runs.items(), ("tab:blue", "tab:orange", "tab:green")):
    ndofs = [r["dofs"]["total"] for r in kept["history"]]
    ax.loglog(ndofs, [r["estimator"] for r in kept["history"]], "s-", color=colour,
              label=f"η, {name}")
    ax.loglog(ndofs, [r["e_tot"] for r in kept["history"]], "o:", color=colour,
              label=f"e_tot (3.124), {name}")
ax.set_xlabel("degrees of freedom N")
ax.set_ylabel("estimator / error")
ax.set_title("Example 3.46 with Coulomb friction")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7, ncol=2)
save_figure(fig, OUT / "thesis_convergence.png")

# %% [markdown]
# The refinement concentrates where the thesis found it: at the corners ($\sigma$
# singular, the large `asymmetry` indicators of Table 4.2), along $\Gamma_N$ where $t_0$
# switches off, and on $\Gamma_C$ (the `friction` and contact terms). The maximum strategy
# refines only a handful of elements per step (the indicators differ by orders of
# magnitude, so few reach half the maximum): slow progress per solve, as the thesis noted
# for Table 4.1. The fraction and Dörfler strategies refine more per step, the fraction
# strategy also elements with small indicators (Figs. 4.9-4.13: "the algorithm also
# refines triangles inside the domain").
#
# $\eta$ decreases, but it will not tend to zero, whatever the strategy. The reason is in
# the two lower corners. $\lambda_n \in C_{\tilde h}$ vanishes at the ends of $\Gamma_C$
# (3.61), so there the discrete solution has $u_n = g = 0.01$, while $u = 0$ on the
# clamped sides $\Gamma_D$: the boundary data *jump* at the corners. Near a displacement
# jump $\sigma \sim 1/r$, which is not square integrable, and the asymmetry indicator of
# the corner element stays the same however small the element (the constant
# $\eta_{as}^{\max}$ of Table 4.2). The estimator reports a real defect of the data; with
# $g = 0$ at the ends it disappears (Exercise 3).

# %%
results = {
    "quick": QUICK, "alpha": alpha,
    "marking_example": {s: int(m.sum()) for s, m in marked_sets.items()},
    "marking_share": {s: float(np.sum(eta[m] ** 2) / np.sum(eta**2))
                      for s, m in marked_sets.items()},
    "l_shape": {name: {"ndofs": [r["dofs"]["total"] for r in kept["history"]],
                       "errors": kept["errors"], "etas": [r["estimator"] for r in kept["history"]],
                       "rates": l_rates[name], "effectivity": effectivity_l[name]}
                for name, kept in l_runs.items()},
    "thesis": {name: [{k: r[k] for k in ("step", "elements", "estimator", "e_tot", "effectivity",
                                         "marked", "converged")}
                      | {"ndof": r["dofs"]["total"]} for r in kept["history"]]
               for name, kept in thesis_runs.items()},
}
print(f"wrote {save_results('07_adaptivity', results)}")

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/07_adaptivity_solutions.py`.
#
# 1. **The Dörfler parameter.** Run Dörfler marking on the L-shape with
#    $\theta \in \{0.2, 0.5, 0.8\}$. Compare the rates, the number of SOLVE steps needed
#    to reach $N \approx 5000$ and the error there. What happens as $\theta \to 1$?
# 2. **Which terms refine Example 3.46?** Run the fraction strategy with the indicator
#    restricted to $\eta_{\sigma,T}$ (4.15) (mark with `Estimate.eta_sigma` in a loop of
#    your own, using `ngdual.afem.refine` and `BoundaryMeshes.follow`) and compare the
#    meshes with those of $\eta_{tot,T}$. Which terms put the refinement on $\Gamma_N$ and
#    $\Gamma_C$?
# 3. **The corners of Example 3.46.** Refine `thesis-3.46-frictionless` uniformly and
#    with Dörfler marking ($\theta = 0.5$), once with the gap $g = 0.01$ and once with
#    $g = 0$ (`nd.load_scene(..., ["contact.gap='0'"])`). Compare $\eta$, its rate
#    (`fitted_rate`) and the largest asymmetry indicator. Explain the difference.
