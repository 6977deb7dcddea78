# %% [markdown]
# # Tutorial 7: Adaptive refinement
#
# **Run time** on a 2-core laptop: about 30 s; about 8 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 07 --quick`).
#
# **The idea in words.** Contact solutions are rough where the contact zone ends and at
# corners, so refining the mesh everywhere wastes most of the unknowns. The adaptive loop
# solves, estimates the error per triangle, marks the triangles with the largest share of
# the estimate and refines only those, then repeats. The pictures show the meshes it
# builds and the error against the number of unknowns, uniform and adaptive.
#
# **Problem.** Solutions of contact problems are not smooth: $\sigma$ is singular at
# corners where boundary conditions change, and at the ends of the contact zone. Uniform
# refinement then converges slowly. The model case: an L-shaped domain with a re-entrant
# corner whose exact solution (Williams) is known. Near a corner of interior angle
# $2\omega = 3\pi/2$ with free sides $u \sim r^\alpha g(\theta)$ and
# $\sigma \sim r^{\alpha-1}$, with $\alpha \in (0, 1)$ the root of
# $\sin(2\omega\alpha) + \alpha\sin(2\omega) = 0$; uniform refinement gives
# $e \sim h^\alpha \sim N^{-\alpha/2}$ in the number $N$ of unknowns, while PEERS could
# reach $N^{-1/2}$ for smooth solutions.
#
# **Discretisation.** PEERS (3.61) on netgen meshes refined by bisection with conforming
# closure; the coarse boundary meshes $\tilde h$ and $\hat h$ follow the refinement,
# nested, with $\tilde h \approx 2h$ locally. The indicators $\eta_{tot,T}$ of (4.50)
# (Tutorial 6) say where to refine.
#
# **What you will learn.** The adaptive loop SOLVE → ESTIMATE → MARK → REFINE, one step
# of each by hand with the public API, then the whole loop by hand, five lines a step: with
# the maximum, fixed-fraction (Section 4.2) or Dörfler marking it restores the optimal rate
# $N^{-1/2}$ on the L-shape (`nd.rates.fitted_rate`: the order in $h_N = N^{-1/2}$,
# $e \sim N^{-\mathrm{rate}/2}$). `nd.adapt` is the same loop, with stopping rules and a
# history of every step.
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
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("07_adaptivity")
QUICK = lesson.quick
RUNS = {"uniform": ("max", 0.0, 3 if QUICK else 5),
        "max": ("max", 0.5, 4 if QUICK else 10),
        "fraction": ("fraction", 0.2, 4 if QUICK else 9),
        "dorfler": ("dorfler", 0.5, 6 if QUICK else 11)}
THETAS = {"max": 0.5, "fraction": 0.2, "dorfler": 0.5}    # of the MARK step by hand

# %% [markdown]
# ## The L-shape
#
# $(-1,1)^2$ without the quarter $(0,1)\times(-1,0)$, traction free ($\Gamma_N$) on the
# two sides at the re-entrant corner, $u = u_{\mathrm{exact}}$ ($\Gamma_D$) on the others.
# `nd.verification.corner` holds the scene, Williams' solution written as scene
# expressions in $x$ and $y$, and the exact error of PEERS,
# $(\|\sigma - \sigma_h\|^2 + \|\operatorname{div}\sigma_h\|^2 + \|u - u_h\|^2
# + \|\eta - \eta_h\|^2)^{1/2}$.

# %%
l_shape = nd.verification.corner.l_shape_scene()
alpha = nd.verification.corner.corner_exponent()
exact = nd.verification.corner.exact_fields()
lesson.save(nd.plot_geometry(l_shape, level=1), "geometry")
print(f"corner exponent alpha = {alpha:.4f}: the rate of uniform refinement")

# %% [markdown]
# ## SOLVE
#
# `nd.build_mesh` meshes the geometry on a level; `nd.BoundaryMeshes` groups the fine
# boundary edges into the coarse meshes $\tilde h$, $\hat h$ of the boundary multipliers;
# `nd.solve_on_mesh` assembles and solves on that mesh. The von Mises stress shows the
# singularity: the colour scale ends at a percentile (stated on the colour bar), else the
# re-entrant corner would take all of it.

# %%
mesh = nd.build_mesh(l_shape.geometry, 1)
coarse = nd.BoundaryMeshes.for_scene(l_shape, mesh)
solution = nd.solve_on_mesh(l_shape, mesh, coarse)
print(f"{mesh.ne} triangles, exact error {nd.verification.corner.exact_error(solution, exact):.3e}")
lesson.save(nd.plot_von_mises(mesh, nd.fields(solution).sigma, l_shape.material.nu,
                              "SOLVE: von Mises stress on the initial mesh"), "solve")

# %% [markdown]
# ## ESTIMATE
#
# `nd.estimate` returns the indicators of (4.50); `indicators` holds $\eta_{tot,T}$ per element.

# %%
estimate = nd.estimate(solution)
indicators = estimate.indicators
points, triangles = nd.mesh_arrays(mesh)
lesson.save(nd.plot_element_field(points, triangles, indicators,
                                  r"ESTIMATE: $\eta_{tot,T}$ of (4.50)", r"$\eta_{tot,T}$"),
            "estimate")

# %% [markdown]
# ## MARK
#
# Marking is a pure function of the indicators $\eta_T \ge 0$ and $\theta \in [0, 1]$:
#
# * **max** (Section 4.2): refine $T$ if $\eta_T \ge \theta\max_{T'}\eta_{T'}$;
# * **fraction** (Section 4.2): refine the $\lceil\theta N_T\rceil$ largest;
# * **Dörfler**: a smallest set $\mathcal{M}$ with
#   $\sum_{T\in\mathcal{M}} \eta_T^2 \ge \theta\sum_T \eta_T^2$, the *bulk* of the error.
#
# Only Dörfler controls how much of $\eta^2$ is refined; optimal rates are proven for it.

# %%
marked = {strategy: nd.mark(indicators, theta, strategy) for strategy, theta in THETAS.items()}
for strategy, chosen in marked.items():
    share = np.sum(indicators[chosen] ** 2) / np.sum(indicators**2)
    print(f"{strategy:8s} theta = {THETAS[strategy]}: {chosen.sum():3d} of {len(indicators)} "
          f"elements, {100 * share:5.1f} % of eta^2")
lesson.save(nd.plot_mesh(points, triangles, "MARK: Dörfler, theta = 0.5",
                         marked=marked["dorfler"]), "mark")

# %% [markdown]
# ## REFINE
#
# `nd.refine_with_boundary` bisects the marked triangles, closes the mesh conformingly and
# carries the coarse boundary meshes over to it: nested, with $\tilde h \approx 2h$ locally.

# %%
refined, refined_coarse = nd.refine_with_boundary(l_shape, mesh, coarse, marked["dorfler"])
lesson.save(nd.plot_mesh(*nd.mesh_arrays(refined), f"REFINE: {mesh.ne} -> {refined.ne} triangles"),
            "refine")

# %% [markdown]
# ## The loop
#
# The four steps, repeated from the same initial mesh; each step keeps the number of
# unknowns $N$, the estimate $\eta$, the exact error and the mesh. The last solve is not
# marked. Four runs:


# %%
def run(marking: str, theta: float, steps: int) -> dict:
    """SOLVE, ESTIMATE, MARK, REFINE on the L-shape from level 1: ``steps`` solves."""
    kept = {"ndofs": [], "etas": [], "errors": [], "meshes": []}
    mesh = nd.build_mesh(l_shape.geometry, 1)
    coarse = nd.BoundaryMeshes.for_scene(l_shape, mesh)
    for step in range(steps):
        solution = nd.solve_on_mesh(l_shape, mesh, coarse)                      # SOLVE
        estimate = nd.estimate(solution)                                        # ESTIMATE
        last = step == steps - 1
        marked = None if last else nd.mark(estimate.indicators, theta, marking)  # MARK
        kept["ndofs"].append(int(sum(solution.problem.spaces.dofs().values())))
        kept["etas"].append(estimate.total)
        kept["errors"].append(nd.verification.corner.exact_error(solution, exact))
        kept["meshes"].append((*nd.mesh_arrays(mesh), marked))
        if not last:
            mesh, coarse = nd.refine_with_boundary(l_shape, mesh, coarse, marked)  # REFINE
    kept["rates"] = {"error": nd.rates.fitted_rate(kept["ndofs"][-3:], kept["errors"][-3:]),
                     "eta": nd.rates.fitted_rate(kept["ndofs"][-3:], kept["etas"][-3:])}
    kept["effectivity"] = [e / error for e, error in zip(kept["etas"], kept["errors"])]
    return kept


runs = {name: run(*settings) for name, settings in RUNS.items()}
for name, kept in runs.items():
    print(f"{name:8s}: N = {kept['ndofs'][0]} .. {kept['ndofs'][-1]}, error "
          f"{kept['errors'][0]:.3e} -> {kept['errors'][-1]:.3e}; rates (last 3 steps): error "
          f"{kept['rates']['error']:.3f}, eta {kept['rates']['eta']:.3f}; eta/e in "
          f"[{min(kept['effectivity']):.2f}, {max(kept['effectivity']):.2f}]")

# %% [markdown]
# Uniform refinement converges at about the corner exponent $\alpha \approx 0.54$, all
# adaptive strategies at about the optimal rate 1 (rates from three steps are rough). The
# estimator follows the error: it overestimates it by a factor between about 2 and 5.

# %% [markdown]
# `nd.adapt(scene, marking, theta, steps)` runs this loop and returns one record per step
# (DOFs, $\eta$ and its terms, the norms of Tables 3.2/3.3, timings), and it stops by
# itself: at a tolerance `tol` of the relative estimate, when the estimate stalls, when the
# next mesh would not fit in memory, ... (`stopped_by` in its last record says which). On
# the Dörfler run it computes what the loop above computed:

# %%
history = nd.adapt(l_shape, *RUNS["dorfler"], level=1)
same = [r["dofs"]["total"] for r in history] == runs["dorfler"]["ndofs"]
print(f"nd.adapt: the same unknowns at every step: {same}; stopped by "
      f"{history[-1]['stopped_by']}")

# %%
fig, ax = plt.subplots(figsize=(7, 5))
for (name, kept), colour in zip(runs.items(), ("k", "tab:blue", "tab:orange", "tab:green")):
    ax.loglog(kept["ndofs"], kept["errors"], "o-", color=colour, label=f"error, {name}")
    ax.loglog(kept["ndofs"], kept["etas"], "s--", color=colour, ms=4, label=f"η, {name}")
n_ref = np.array([runs["uniform"]["ndofs"][0], 2e4])
e_ref = 0.8 * runs["uniform"]["errors"][0]
ax.loglog(n_ref, e_ref * (n_ref / n_ref[0]) ** (-alpha / 2), "k:", lw=1,
          label=f"N^(-α/2), α = {alpha:.3f}")
ax.loglog(n_ref, e_ref * (n_ref / n_ref[0]) ** -0.5, "k-.", lw=1, label="N^(-1/2)")
ax.set(xlabel="degrees of freedom N", ylabel="error / estimator",
       title="L-shape, nd.verification.corner singularity")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7, ncol=2)
lesson.save(fig, "l_shape_convergence")

points, triangles, _ = runs["dorfler"]["meshes"][-1]
lesson.save(nd.plot_mesh(points, triangles, f"Dörfler, last step: {len(triangles)} triangles"),
            "l_shape_dorfler_mesh")

# %% [markdown]
# The refinement concentrates at the re-entrant corner, where $\sigma \sim r^{\alpha-1}$.
# On a contact problem the same loop also refines along $\Gamma_N$ where the traction
# switches off and at the ends of the contact zone (Example 3.46: Figs. 4.1-4.13,
# `ngdual figures`); where the data themselves jump, as at the lower corners of Example
# 3.46 with $g \ne 0$, $\eta$ stalls whatever the strategy (Exercise 3).

# %%
lesson.results({
    "alpha": alpha, "elements": int(mesh.ne),
    "marking_example": {s: int(m.sum()) for s, m in marked.items()},
    "marking_share": {s: float(np.sum(indicators[m] ** 2) / np.sum(indicators**2))
                      for s, m in marked.items()},
    "refined_elements": int(refined.ne),
    "adapt_matches_the_loop": same,
    "l_shape": {name: {k: kept[k] for k in ("ndofs", "errors", "etas", "rates", "effectivity")}
                for name, kept in runs.items()},
})

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/07_adaptivity_solutions.py`.
#
# 1. **The Dörfler parameter.** Run Dörfler marking on the L-shape with
#    $\theta \in \{0.2, 0.5, 0.8\}$. Compare the rates, the number of SOLVE steps needed
#    to reach $N \approx 5000$ and the error there. What happens as $\theta \to 1$?
# 2. **Which terms refine Example 3.46?** Run the fraction strategy with the indicator
#    restricted to $\eta_{\sigma,T}$ (4.15) (mark with `Estimate.eta_sigma` in the loop
#    above) and compare the
#    meshes with those of $\eta_{tot,T}$. Which terms put the refinement on $\Gamma_N$ and
#    $\Gamma_C$?
# 3. **The corners of Example 3.46.** Refine `thesis-3.46-frictionless` uniformly and
#    with Dörfler marking ($\theta = 0.5$), once with the gap $g = 0.01$ and once with
#    $g = 0$ (`nd.load_scene(..., ["contact.gap='0'"])`). Compare $\eta$, its rate
#    (`nd.rates.fitted_rate`) and the largest asymmetry indicator. Explain the difference.
