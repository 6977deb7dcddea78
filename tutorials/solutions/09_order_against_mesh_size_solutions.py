# %% [markdown]
# # Solutions to Tutorial 9: Order against mesh size
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt

import ngdual as nd

lesson = nd.Lesson("09_order_against_mesh_size_solutions")
QUICK = lesson.quick
LEVELS = ({0: [1, 2, 3], 1: [1, 2, 3], 2: [1, 2]} if QUICK
          else {0: [1, 2, 3, 4, 5], 1: [1, 2, 3, 4], 2: [1, 2, 3]})
FACET_LEVELS = [2, 3] if QUICK else [2, 3, 4, 5]

case = nd.verification.manufactured_case("frictionless")
scene = case.scene()


def study(levels, **arguments) -> list[dict]:
    """Unknowns, seconds and the L2 errors of sigma, u, eta of nd.solve on every level."""
    rows = []
    for level in levels:
        solution = nd.solve(scene, level, **arguments)
        errors = nd.verification.volume_errors(case, solution)
        rows.append({"level": level, "ndof": solution.problem.fes.ndof,
                     "seconds": solution.timings["total"],
                     **{q: errors[q] for q in ("sigma", "u", "eta")}})
    return rows


def orders(rows: list[dict], quantity: str) -> list[float | None]:
    return nd.rates.observed_rates([r["ndof"] for r in rows], [r[quantity] for r in rows])


# %% [markdown]
# ## Exercise 1: the displacement and the rotation
#
# The displacement converges like the stress, at $k + 1$. The rotation, continuous
# $P_{k+1}$, is more accurate on coarse meshes than its order promises (superconvergent
# at $k = 0$, as on linear elasticity, `docs/theory/order.md`) and approaches $k + 1$.

# %%
runs = {k: study(levels, order=k) for k, levels in LEVELS.items()}
by_order = {}
for k, rows in runs.items():
    by_order[str(k)] = {q: orders(rows, q)[-1] for q in ("sigma", "u", "eta")}
    print(f"k = {k}: last observed orders " + ", ".join(f"{q} {a:.2f}"
                                                        for q, a in by_order[str(k)].items()))

# %% [markdown]
# ## Exercise 2: the multipliers at order 0
#
# The $P_0$ multipliers on the fine edges pair with the normal traces of $RT_0$ edge by
# edge. The stress in the volume hardly changes — its error is that of $RT_0$ — while
# the solver changes: the facet multipliers are solved by the hybridised system of order
# $k$ (`nd.solvers.hybrid_order`), the thesis' multipliers by the thesis' one.

# %%
pairings = {"coarse": study(FACET_LEVELS),
            "facet": study(FACET_LEVELS, multipliers="facet")}
fig, ax = plt.subplots(figsize=(6, 4.5))
for name, rows in pairings.items():
    ax.loglog([r["ndof"] for r in rows], [r["sigma"] for r in rows], "o-",
              label=f"PEERS$_0$, {name} multipliers")
ax.set(xlabel="unknowns N", ylabel=r"$\|\sigma - \sigma_h\|_{L^2}$",
       title="order 0: the thesis' hats on 2h against P0 on the fine edges")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
lesson.save(fig, "multipliers_at_order_0")
for name, rows in pairings.items():
    print(f"{name:6s}: sigma error {rows[-1]['sigma']:.3e} in {rows[-1]['seconds']:.2f} s "
          f"on level {rows[-1]['level']}, order {orders(rows, 'sigma')[-1]:.2f}")

# %%
lesson.results({
    "orders": by_order,
    "pairings": {name: {"sigma": [r["sigma"] for r in rows],
                        "seconds": [r["seconds"] for r in rows],
                        "sigma_order": orders(rows, "sigma")[-1]}
                 for name, rows in pairings.items()},
})
