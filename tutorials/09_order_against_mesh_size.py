# %% [markdown]
# # Tutorial 9: Order against mesh size — what accuracy costs
#
# **Run time** on a 2-core laptop: about 7 s; about 6 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 09 --quick`).
#
# **The idea in words.** Accuracy can be bought with smaller triangles or with higher
# polynomial order. On a problem with a known exact solution this tutorial measures what
# each costs: the error against the number of unknowns and against the run time, uniform
# and adaptive, for the orders 0, 1 and 2 of the stress-based method.
#
# **Problem.** The rectangle of Example 3.46, $\Omega = (-4, 4) \times (-1, 1)$, pressed onto
# a rigid foundation along its bottom side $\Gamma_C$ without friction, clamped on the left
# and right sides ($\Gamma_D$), loaded on the top ($\Gamma_N$). The loads are manufactured
# (`nd.verification.manufactured`, case `frictionless`): the exact displacement and
# stress are known, the body touches the foundation exactly on $[-2, 2]$ with the pressure
# $-\sigma_n = 5\,(1 - x^2/4)^2$ and lifts off towards the clamped ends. So every error below
# is measured against the truth.
#
# **Discretisation.** PEERS of order $k$ (Stenberg's PEERS$_k$, `docs/theory/order.md`):
# stress rows in $RT_k$ plus the Curl of element bubbles, $u$ in discontinuous $P_k$, the
# rotation in continuous $P_{k+1}$. $k = 0$ is the thesis' triple (3.61) with the contact
# multipliers on the coarse mesh $\tilde h = 2h$; at $k = 1, 2$ the multipliers are
# discontinuous $P_k$ on the fine edges of $\Gamma_C$, $\lambda_n \ge 0$ on their Bernstein
# coefficients. `nd.solve(scene, level, order=k)` picks the order.
#
# **What you will learn.** On a smooth solution the stress error of PEERS$_k$ falls like
# $h^{k+1}$, i.e. like $N^{-(k+1)/2}$ in the number $N$ of unknowns: refining the mesh
# buys accuracy at a rate fixed by $k$, raising $k$ changes the rate. One idea: to reach a
# given accuracy, a higher order needs far fewer unknowns and less time than a finer mesh,
# although every unknown costs more (larger element blocks, denser matrices).
# And why adaptive refinement adds nothing on a smooth solution: the uniform mesh is
# already optimal for it.
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011: the PEERS triple (3.61), the
# discrete contact problem (3.62)/(3.103), convergence in Section 3.4.
# D. N. Arnold, F. Brezzi, J. Douglas, *PEERS: a new mixed finite element for plane
# elasticity*, Japan J. Appl. Math. 1 (1984). R. Stenberg, *A family of mixed finite elements
# for the elasticity problem*, Numer. Math. 53 (1988). F. Ben Belgacem, Y. Renard, *Hybrid
# finite element methods for the Signorini problem*, Math. Comp. 72 (2003).

# %% [markdown]
# ## Parameters
#
# The uniform levels of each order (level $\ell$ has $32 \cdot 4^{\ell-1}$ triangles), the
# steps of the adaptive runs (from level 1) and the stress error whose cost we compare.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("09_order_against_mesh_size")
QUICK = lesson.quick
LEVELS = ({0: [1, 2, 3], 1: [1, 2, 3], 2: [1, 2]} if QUICK
          else {0: [1, 2, 3, 4, 5], 1: [1, 2, 3, 4], 2: [1, 2, 3]})
STEPS = {0: 4, 1: 4, 2: 3} if QUICK else {0: 8, 1: 7, 2: 6}   # adaptive SOLVE steps
TARGET = 1e-2                          # the relative stress error whose cost we compare

# %% [markdown]
# ## The scene
#
# `case.scene()` writes the manufactured loads as a scene like any other: body force
# $f = -\operatorname{div}\sigma$, the exact traction on the top, the exact displacement
# on the sides, the gap $g = u_n + \lambda_n$.

# %%
case = nd.verification.manufactured_case("frictionless")
scene = case.scene()
lesson.save(nd.plot_geometry(scene, level=1), "geometry")
norm_sigma = nd.verification.volume_errors(case, nd.solve(scene, 1))["norm_sigma"]
print(f"{case.description}; ||sigma||_L2 = {norm_sigma:.4g}")

# %% [markdown]
# ## SOLVE at every order, on every level
#
# For each order $k$ and level: the unknowns $N$, the wall time of `nd.solve` (meshing,
# assembly, the contact solver: `solution.timings["total"]`) and the $L^2$ errors of
# $\sigma$, $u$ and the rotation $\eta$ against the exact solution, integrated exactly
# (`volume_errors`). The observed
# order is ngdual's one rate, $e \sim N^{-\mathrm{order}/2}$ (`nd.rates`); on a
# uniform mesh $N \sim h^{-2}$, so it is the order in $h$.

# %%
runs = {}
for k, levels in LEVELS.items():
    rows = []
    for level in levels:
        solution = nd.solve(scene, level, order=k)
        errors = nd.verification.volume_errors(case, solution)
        rows.append({"level": level, "ndof": solution.problem.fes.ndof,
                     "seconds": solution.timings["total"],
                     **{q: errors[q] for q in ("sigma", "u", "eta")}})
    rates = nd.rates.observed_rates([r["ndof"] for r in rows], [r["sigma"] for r in rows])
    runs[k] = {"rows": rows, "sigma_orders": rates}
    for row, rate in zip(rows, rates):
        print(f"k = {k}, level {row['level']}: N = {row['ndof']:6d}, {row['seconds']:6.2f} s, "
              f"sigma error {row['sigma'] / norm_sigma:.2e} (relative)"
              + ("" if rate is None else f", order {rate:.2f}"))

# %% [markdown]
# Every order does what it promises: the observed order of the stress approaches $k + 1$
# (1, 2, 3; the picture follows the adaptive runs below). On the same mesh PEERS$_1$ is
# one to two orders of magnitude more accurate than PEERS$_0$, PEERS$_2$ again more, for
# about 3 and 6 times the unknowns.

# %% [markdown]
# ## Adaptive refinement at every order
#
# `nd.adapt` runs SOLVE, ESTIMATE, MARK, REFINE (Tutorial 7) at the scene's order: the
# indicators of (4.50) at order $k$ (`docs/theory/estimator.md`), Dörfler marking. An
# `on_step` callback measures the exact stress error of each step and reads the step's
# record: `record["solved_s"]`, the wall time from the start of the run to the step's
# solution (without the time of the callback), is the honest cost of an adaptive solution
# (every coarser step is paid for).


# %%
def adaptive_run(k: int) -> dict:
    """nd.adapt at order k from level 1, with the exact stress error of every step."""
    kept = {"ndof": [], "sigma": [], "seconds": []}

    def on_step(record, solution, estimated, marked):
        kept["ndof"].append(solution.problem.fes.ndof)
        kept["sigma"].append(nd.verification.volume_errors(case, solution)["sigma"])
        kept["seconds"].append(record["solved_s"])

    nd.adapt(case.scene(order=k), steps=STEPS[k], level=1, on_step=on_step)
    kept["sigma_orders"] = nd.rates.observed_rates(kept["ndof"], kept["sigma"])
    return kept


adaptive = {k: adaptive_run(k) for k in STEPS}
for k, kept in adaptive.items():
    uniform = runs[k]["rows"][-1]
    print(f"k = {k}, adaptive: N = {kept['ndof'][0]} -> {kept['ndof'][-1]}, relative stress "
          f"error {kept['sigma'][-1] / norm_sigma:.2e} after {kept['seconds'][-1]:.2f} s; "
          f"uniform level {uniform['level']}: N = {uniform['ndof']}, "
          f"{uniform['sigma'] / norm_sigma:.2e}")

# %% [markdown]
# On this solution adaptivity does not pay: against $N$ its errors lie on or above the
# uniform line $N^{-(k+1)/2}$ (its first steps refine where the indicators are largest,
# which is not where the error is), and against time the loop also pays for every
# coarser step. The solution is smooth on every triangle, so the uniform mesh is already
# the best mesh for it.
# Where the stress is singular, adaptivity is what recovers the order: on Example 3.46
# with consistent ends (singular at the clamped ends of $\Gamma_C$) uniform refinement
# falls to the order of the singularity, about 0.9 at $k = 1$ and 0.8 at $k = 2$, while the
# adaptive loop keeps $k + 1$ (`docs/theory/estimator.md`). Order and adaptivity go
# together: order buys the rate, adaptivity keeps it where the solution is not smooth.

# %%
fig, (ax_n, ax_t) = plt.subplots(1, 2, figsize=(13, 4.8))
for (k, run), colour in zip(runs.items(), ("tab:blue", "tab:orange", "tab:green")):
    error = np.array([r["sigma"] for r in run["rows"]]) / norm_sigma
    ndof = np.array([r["ndof"] for r in run["rows"]])
    ax_n.loglog(ndof, error, "o-", color=colour, label=f"PEERS$_{k}$, uniform")
    slope = ("-1/2", "-1", "-3/2")[k]
    ax_n.loglog(ndof, error[0] * (ndof / ndof[0]) ** (-(k + 1) / 2), ":", color=colour, lw=1,
                label=f"$N^{{{slope}}}$")
    ax_t.loglog([r["seconds"] for r in run["rows"]], error, "o-", color=colour)
    kept = adaptive[k]
    ax_n.loglog(kept["ndof"], np.array(kept["sigma"]) / norm_sigma, "s--", color=colour,
                ms=4, label=f"PEERS$_{k}$, adaptive")
    ax_t.loglog(kept["seconds"], np.array(kept["sigma"]) / norm_sigma, "s--", color=colour,
                ms=4)
for ax, xlabel in ((ax_n, "unknowns N"),
                   (ax_t, "wall time [s] (adaptive: all steps up to this one)")):
    ax.axhline(TARGET, color="k", lw=0.8, ls="-.", label=f"target {TARGET:g}")
    ax.set(xlabel=xlabel, ylabel=r"$\|\sigma - \sigma_h\|_{L^2} / \|\sigma\|_{L^2}$")
    ax.xaxis.set_minor_formatter(plt.NullFormatter())
    ax.grid(True, which="both", alpha=0.3)
ax_n.set_title("stress error against unknowns")
ax_t.set_title("stress error against time")
fig.legend(*ax_n.get_legend_handles_labels(), loc="center right", fontsize=8)
fig.subplots_adjust(right=0.82, wspace=0.25)
fig.suptitle("Manufactured frictionless contact: uniform and adaptive refinement at order k")
lesson.save(fig, "order_against_mesh_size")

# %% [markdown]
# ## What accuracy costs
#
# The unknowns and the time each order needs for a relative stress error of `TARGET`:
# between two levels, $\log e$ interpolated linearly in $\log N$ (the observed order);
# beyond the last level, $N$ extrapolated with the last observed order and the time taken
# as linear in $N$ from the last level (a lower bound for a direct solver), marked `*`;
# reached on the first level already, that level's, marked `<=`.


# %%
def cost_of(rows: list[dict], target: float) -> dict:
    """Unknowns and seconds at which the relative stress error reaches ``target``."""
    n = np.array([r["ndof"] for r in rows], dtype=float)
    t = np.array([r["seconds"] for r in rows])
    e = np.array([r["sigma"] for r in rows]) / norm_sigma
    if e[0] <= target:
        return {"ndof": n[0], "seconds": t[0], "how": "<="}
    i = next((j for j in range(1, len(rows)) if e[j] <= target), len(rows) - 1)
    share = np.log(target / e[i - 1]) / np.log(e[i] / e[i - 1])    # > 1: beyond level i
    ndof = n[i - 1] * (n[i] / n[i - 1]) ** share
    if e[i] <= target:
        return {"ndof": ndof, "seconds": t[i - 1] * (t[i] / t[i - 1]) ** share, "how": ""}
    return {"ndof": ndof, "seconds": t[i] * ndof / n[i], "how": "*"}


costs = {k: cost_of(run["rows"], TARGET) for k, run in runs.items()}
for k, c in costs.items():
    print(f"k = {k}: relative stress error {TARGET:g} with N = {c['ndof']:9.0f} unknowns in "
          f"{c['seconds']:7.2f} s {c['how']}")

# %% [markdown]
# The lowest order pays for its accuracy with unknowns: halving its error takes four
# times as many, so a small target needs a very fine mesh (a 1 % stress error about
# $10^5$ unknowns). Each order more divides the unknowns needed by a large factor, and
# the time with them, although an unknown of PEERS$_1$ or PEERS$_2$ costs 0.9 to 2.2 times
# one of PEERS$_0$ (the hybridised system of order $k$ eliminates larger element blocks and
# factorises a denser matrix; `docs/theory/order.md`). For a rough
# target, 10 % and more, the lowest order is as cheap as any: order pays where accuracy is
# asked for.
#
# The manufactured solution is piecewise smooth, its pieces meeting at $x = \pm 2$, lines
# of every mesh here, so each triangle sees a smooth function and the full order $k + 1$
# appears. Hertz, the flat punch and Cattaneo–Mindlin are singular at the ends of the
# contact zone, which no mesh follows: there uniform refinement converges at the rate the
# singularity allows, whatever $k$, and adaptivity is needed for the order to pay.

# %%
lesson.results({
    "norm_sigma": norm_sigma,
    "runs": {str(k): run for k, run in runs.items()},
    "observed_order": {str(k): run["sigma_orders"][-1] for k, run in runs.items()},
    "target": TARGET,
    "costs": {str(k): c for k, c in costs.items()},
    "adaptive": {str(k): kept for k, kept in adaptive.items()},
})

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/09_order_against_mesh_size_solutions.py`.
#
# 1. **The displacement and the rotation.** Compute the observed orders of $u$ and $\eta$
#    from `runs`. Which reach $k + 1$, and from which side?
# 2. **The multipliers at order 0.** Solve with `nd.solve(scene, level, order=0,
#    multipliers="facet")`: the $P_0$ multipliers on the fine edges instead of the hats on
#    $\tilde h = 2h$. Compare the stress error and the time with the thesis' pairing on the
#    same levels. What does the finer multiplier buy in the volume?
