# %% [markdown]
# # Solutions to Tutorial 7: Adaptive refinement
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("07_adaptivity_solutions")
QUICK = lesson.quick
TARGET_DOFS = 1500 if QUICK else 8000       # Exercise 1: refine until N reaches this
THETAS = [0.2, 0.5, 0.8]
THESIS_STEPS = 3 if QUICK else 5            # Exercise 2
CORNER_STEPS = 4 if QUICK else 9            # Exercise 3
UNIFORM_LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4]


def adapt_until(scene, marking, theta, max_dofs, level=1, indicator="indicators", error=None,
                max_steps=40):
    """SOLVE-ESTIMATE-MARK-REFINE until N >= max_dofs, marking with any indicator array.

    ``indicator`` names an `Estimate` attribute ("indicators", "eta_sigma", "eta_u").
    Returns one row (ndof, eta, error or None) per step, the last mesh and its boundary
    meshes (`nd.BoundaryMeshes`: the fine edges of Γ_N and Γ_C grouped under coarse ones).
    """
    mesh = nd.build_mesh(scene.geometry, level)
    coarse = nd.BoundaryMeshes.for_scene(scene, mesh)
    rows = []
    for _ in range(max_steps):
        solution = nd.solvers.solve_problem(nd.assemble(scene, mesh, coarse))              # SOLVE
        estimated = nd.estimate(solution)                                       # ESTIMATE
        ndof = int(sum(solution.problem.spaces.dofs().values()))
        rows.append({"ndof": ndof, "eta": estimated.total,
                     "error": error(solution) if error else None})
        if ndof >= max_dofs:
            break
        marked = nd.mark(getattr(estimated, indicator), theta, marking)         # MARK
        mesh, coarse = nd.refine_with_boundary(scene, mesh, coarse, marked)  # REFINE
    return rows, mesh, coarse


# %% [markdown]
# ## Exercise 1: the Dörfler parameter
#
# Every $\theta$ restores a rate close to the optimal 1 on the L-shape: the bulk
# criterion refines around the corner whatever $\theta$. Small $\theta$ refines few
# elements per step, so more SOLVE steps are needed to reach the same $N$ (each costing a
# solve), with a slightly better error per unknown. Large $\theta$ refines more and more
# elements away from the corner; $\theta = 1$ marks every element with $\eta_T > 0$, i.e.
# uniform refinement, and the rate falls back to $\alpha \approx 0.54$. $\theta \approx 0.5$
# is the usual compromise.

# %%
l_shape = nd.verification.corner.l_shape_scene()  # Williams' corner solution
exact = nd.verification.corner.exact_fields()


def exact_error(solution) -> float:
    return nd.verification.corner.exact_error(solution, exact)


dorfler, curves = {}, {}
for theta in THETAS:
    rows, _, _ = adapt_until(l_shape, "dorfler", theta, TARGET_DOFS, error=exact_error)
    ndofs, errors = [r["ndof"] for r in rows], [r["error"] for r in rows]
    curves[theta] = (ndofs, errors)
    dorfler[str(theta)] = {"steps": len(rows), "ndof": ndofs[-1], "error": errors[-1],
                           "rate": nd.rates.fitted_rate(ndofs[-3:], errors[-3:])}
    row = dorfler[str(theta)]
    print(f"theta = {theta}: {row['steps']:2d} SOLVE steps to N = {row['ndof']:5d}, error "
          f"{row['error']:.3e}, rate (last 3 steps) {row['rate']:.3f}")

# %%
fig, ax = plt.subplots(figsize=(6.5, 4.5))
for theta, (ndofs, errors) in curves.items():
    ax.loglog(ndofs, errors, "o-", ms=3, label=rf"Dörfler, $\theta = {theta}$")
first_n, first_e = curves[THETAS[0]][0][0], curves[THETAS[0]][1][0]
reference = np.array([first_n, TARGET_DOFS])
ax.loglog(reference, first_e * (reference / first_n) ** -0.5, "k:", label=r"$N^{-1/2}$ (optimal)")
ax.set_xlabel("degrees of freedom N")
ax.set_ylabel("exact error e (Williams' nd.verification.corner solution)")
ax.set_title(r"Exercise 1: Dörfler marking on the L-shape for three $\theta$")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
lesson.save(fig, "dorfler_theta")

# %% [markdown]
# ## Exercise 2: which terms refine Example 3.46?
#
# Marking with $\eta_{\sigma,T}$ alone leaves out $\eta_{u,T}$ (tiny here: strains, not
# stresses) and, more importantly, the friction term on $\Gamma_C$ and the Neumann term on
# $\Gamma_N$. Without them the refinement goes to the corners (asymmetry) and much less
# along $\Gamma_N$ and $\Gamma_C$: the Neumann term pulls the refinement to where $t_0$
# switches off, the friction term to the contact boundary. Counted below: the fine edges
# on $\Gamma_N$ (top) and $\Gamma_C$ (bottom) of the final meshes.


# %%
def fine_edges(boundary_mesh) -> int:
    """The number of fine edges under a coarse boundary mesh (h~ of Γ_N or of Γ_C)."""
    return len(boundary_mesh.fine_edges()[0])


thesis = nd.load_scene("thesis-3.46-coulomb")     # Γ_N is the top, Γ_C the bottom
by_indicator, meshes = {}, {}
for indicator in ("indicators", "eta_sigma"):
    rows, mesh, coarse = adapt_until(thesis, "fraction", 0.2, 10**9, level=2,
                                     indicator=indicator, max_steps=THESIS_STEPS)
    meshes[indicator] = mesh
    by_indicator[indicator] = {"elements": mesh.ne, "top_edges": fine_edges(coarse.neumann),
                               "bottom_edges": fine_edges(coarse.contact),
                               "eta": [r["eta"] for r in rows]}
    row = by_indicator[indicator]
    print(f"marking with {indicator:9s}: {row['elements']} triangles, {row['top_edges']} "
          f"edges on Gamma_N, {row['bottom_edges']} on Gamma_C; eta_tot "
          f"{row['eta'][0]:.3e} -> {row['eta'][-1]:.3e}")

# %%
fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
for ax, (indicator, label) in zip(axes, (("indicators", r"$\eta_{tot,T}$ (4.50)"),
                                         ("eta_sigma", r"$\eta_{\sigma,T}$ (4.15) only"))):
    points, triangles = nd.mesh_arrays(meshes[indicator])
    ax.triplot(points[:, 0], points[:, 1], triangles, color="0.3", lw=0.3)
    row = by_indicator[indicator]
    ax.set_title(f"marked with {label}: {row['elements']} triangles, {row['top_edges']} "
                 f"edges on $\\Gamma_N$ (top), {row['bottom_edges']} on $\\Gamma_C$ (bottom)",
                 fontsize=9)
    ax.set_aspect("equal")
    ax.set_ylabel("$x_2$")
axes[-1].set_xlabel("$x_1$")
fig.suptitle(f"Exercise 2: Example 3.46 (Coulomb), fraction marking, {THESIS_STEPS} steps")
fig.tight_layout()
lesson.save(fig, "meshes_by_indicator")

# %% [markdown]
# ## Exercise 3: the corners of Example 3.46
#
# With $g = 0.01$ the multiplier $\lambda_n \in C_{\tilde h}$ vanishes at the ends of
# $\Gamma_C$, so $u_n = g$ there, while $u = 0$ on $\Gamma_D$: the displacement jumps at
# the lower corners and $\sigma \sim 1/r$ is not square integrable. Under uniform
# refinement the asymmetry indicator of the corner element stays at the same value, and
# $\eta$ stalls (rate near 0). With $g = 0$ the data are compatible: the largest asymmetry
# indicator shrinks with $h$ and $\eta$ decreases fast. Dörfler marking first chases the
# largest $\eta_{tot,T}$, which for $g = 0$ sit at the ends of $\Gamma_N$ (the Neumann
# terms), and reaches the lower corners only after a few steps: the quick run is still
# pre-asymptotic. Over 9 steps (without `NGDUAL_QUICK`) $\eta$ decreases at a rate of
# about 1.4 for $g = 0$, while for $g = 0.01$ it stalls near 420, its largest asymmetry
# indicator frozen at about 160.

# %%
corners = {}
for gap in ("0.01", "0"):
    scene = nd.load_scene("thesis-3.46-frictionless", [f"contact.gap='{gap}'"])
    solutions = [nd.solve(scene, level) for level in UNIFORM_LEVELS]
    uniform = [nd.estimate(solution) for solution in solutions]
    uniform_ndofs = [int(sum(s.problem.spaces.dofs().values())) for s in solutions]
    history = nd.adapt(scene, "dorfler", 0.5, CORNER_STEPS, level=1)
    ndofs, etas = [r["dofs"]["total"] for r in history], [r["estimator"] for r in history]
    corners[gap] = {"uniform_ndofs": uniform_ndofs, "uniform_eta": [e.total for e in uniform],
                    "uniform_as_max": [float(np.sqrt(e.terms["asymmetry"].max()))
                                       for e in uniform],
                    "dorfler_ndofs": ndofs, "dorfler_etas": etas,
                    "dorfler_rate": nd.rates.fitted_rate(ndofs[-3:], etas[-3:])}
    row = corners[gap]
    print(f"g = {gap:4s} uniform levels {UNIFORM_LEVELS}: eta {np.round(row['uniform_eta'], 1)}, "
          f"max eta_as,T {np.round(row['uniform_as_max'], 1)}")
    print(f"         Dörfler: eta {np.round(etas, 1)}, rate {row['dorfler_rate']:.2f}")

# %%
# %%
fig, ax = plt.subplots(figsize=(6.5, 4.5))
for gap, colour in (("0.01", "tab:red"), ("0", "tab:blue")):
    row = corners[gap]
    ax.loglog(row["uniform_ndofs"], row["uniform_eta"], "s--", color=colour,
              label=f"g = {gap}, uniform")
    ax.loglog(row["dorfler_ndofs"], row["dorfler_etas"], "o-", color=colour, ms=3,
              label=rf"g = {gap}, Dörfler $\theta = 0.5$")
ax.set_xlabel("degrees of freedom N")
ax.set_ylabel(r"estimator $\eta = (\sum_T \eta_{tot,T}^2)^{1/2}$")
ax.set_title("Exercise 3: incompatible data (g = 0.01) stall the estimator")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
lesson.save(fig, "corners_eta")

# %%
lesson.results({"dorfler": dorfler, "by_indicator": by_indicator, "corners": corners})
