# %% [markdown]
# # Solutions to Tutorial 10: A goal and a tolerance
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("10_goal_and_tolerance_solutions")
QUICK = lesson.quick
TOL = 0.03 if QUICK else 0.01


def run(scene, steps: int = 20, **arguments) -> dict:
    """nd.adapt to TOL (at most ``steps`` solves): unknowns, relative estimate and time per
    step, the last mesh, how it stopped."""
    kept = {"ndof": [], "relative_estimate": [], "seconds": []}

    def on_step(record, solution, estimated, marked):
        kept["ndof"].append(record["dofs"]["total"])
        kept["relative_estimate"].append(record["relative_estimate"])
        kept["seconds"].append(record["elapsed_s"])
        kept["mesh"] = nd.mesh_arrays(solution.problem.fes.mesh)

    # growth=1: Doerfler's own sets, so that the meshes show where the goal marks and theta
    # alone sets a step (a tolerance run's least growth, 1.5 by default, refines the
    # estimate's peaks once more and would hide both)
    history = nd.adapt(scene, goal="pressure", tol=TOL, steps=steps, on_step=on_step,
                       **{"growth": 1.0, **arguments})
    kept["stopped_by"] = history[-1]["stopped_by"]
    return kept


# %% [markdown]
# ## 1. A window
#
# Without a window the goal is the error on all of $\Gamma_C$, infinite for the punch:
# its relative estimate stays near 10 % while the loop refines the two punch edges, where
# the pressure is singular. After three such solves the run stops as `"singular"` and says
# why (a `ToleranceWarning`, and its last record's `stop_message`).
# With the window $|x| < 0.125$ the edges count only as far as their stress error
# pollutes the core: the run stops by its tolerance, and its smallest triangles lie in
# and next to the core.

# %%
punch = nd.load_scene("flat-punch")
windowed = run(punch, window=(-0.125, 0.125))
everywhere = run(punch)


def smallest_triangles_x(points: np.ndarray, triangles: np.ndarray, count: int = 50):
    """The |x| of the centres of the ``count`` smallest triangles."""
    corners = points[triangles]
    a, b = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    area = 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    return np.abs(corners.mean(axis=1)[np.argsort(area)[:count], 0])


core_share = float(np.mean(smallest_triangles_x(*windowed["mesh"]) < 0.2))
print(f"window: stopped by {windowed['stopped_by']} after {len(windowed['ndof'])} solves, "
      f"N = {windowed['ndof'][-1]}; {core_share:.0%} of its 50 smallest triangles within "
      f"|x| < 0.2")
print("no window: relative estimates", np.round(everywhere["relative_estimate"], 3).tolist(),
      f"stopped by {everywhere['stopped_by']}")
points, triangles = windowed["mesh"]
fig, ax = plt.subplots(figsize=(10, 2.6), layout="constrained")
ax.triplot(points[:, 0], points[:, 1], triangles, lw=0.3, color="k")
ax.axvspan(-0.125, 0.125, color="tab:green", alpha=0.15, label="window")
ax.set(xlim=(-0.6, 0.6), ylim=(-0.01, 0.3), aspect="equal",
       title="flat punch, pressure goal on the core: the last mesh")
ax.legend(loc="upper right")
lesson.save(fig, "punch_window_mesh")

# %% [markdown]
# ## 2. Order
#
# The same goal and tolerance at order 1 and 2 (the multipliers on the fine edges): fewer
# unknowns per digit of accuracy; whether the time falls too depends on the tolerance.

# %%
hertz = nd.load_scene("hertz-cylinder")
orders = {k: run(hertz, order=k) for k in (0, 1, 2)}
for k, kept_k in orders.items():
    print(f"order {k}: {len(kept_k['ndof'])} solves, N = {kept_k['ndof'][-1]}, "
          f"{kept_k['seconds'][-1]:.2f} s, stopped by {kept_k['stopped_by']}")

# %% [markdown]
# ## 3. Growth
#
# Dörfler's $\theta$ is the share of the squared estimate the marked triangles carry: a
# larger $\theta$ marks more triangles, so $N$ grows faster per step and the loop needs
# fewer solves; a smaller one takes more, smaller steps. The time is not monotone in
# $\theta$: a fast-growing run pays for refining triangles whose error was already small,
# and its last step overshoots the tolerance.

# %%
growth, runs_by_theta = {}, {}
for theta in (0.5, 0.8, 0.95):
    kept_t = runs_by_theta[theta] = run(hertz, theta=theta)
    ndof = np.array(kept_t["ndof"], dtype=float)
    growth[str(theta)] = {"solves": len(ndof),
                          "growth": float(np.exp(np.mean(np.log(ndof[1:] / ndof[:-1])))),
                          "seconds": kept_t["seconds"][-1]}
    print(f"theta = {theta}: {growth[str(theta)]['solves']} solves, N x "
          f"{growth[str(theta)]['growth']:.2f} per step, {kept_t['seconds'][-1]:.2f} s")

fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
for theta, kept_t in runs_by_theta.items():
    ax.semilogy(range(1, len(kept_t["ndof"]) + 1), kept_t["ndof"], "o-", label=f"theta {theta}")
ax.set(xlabel="solve", ylabel="unknowns N", title="hertz-cylinder, pressure goal to TOL")
ax.legend()
lesson.save(fig, "growth")

# %%
lesson.results({
    "window": {"stopped_by": windowed["stopped_by"], "solves": len(windowed["ndof"]),
               "core_share": core_share},
    "no_window_estimates": everywhere["relative_estimate"],
    "no_window_stopped_by": everywhere["stopped_by"],
    "orders": {str(k): {"ndof": v["ndof"][-1], "seconds": v["seconds"][-1],
                        "stopped_by": v["stopped_by"]} for k, v in orders.items()},
    "growth": growth,
})
