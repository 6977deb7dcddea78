# %% [markdown]
# # Solutions to Tutorial 2: Locking-free PEERS as ν → ½
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("02_locking_solutions")
QUICK = lesson.quick
LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]
NUS = [0.3, 0.49, 0.499, 0.4999]

# %% [markdown]
# ## Exercise 1: $P_2$ on the same meshes
#
# We reuse the manufactured divergence-free solution of the tutorial. $P_2$ is much
# better than $P_1$, but on general triangulations it is still not robust in $\lambda$:
# the error ratio between $\nu = 0.4999$ and $\nu = 0.3$ exceeds one noticeably
# (locking-free conforming Lagrange elements need degree $\ge 4$ with special meshes,
# Scott-Vogelius).

# %%
P = {"p": "(T**2*(1 - T)**2)", "dp": "(2*T - 6*T**2 + 4*T**3)",
     "d2p": "(2 - 12*T + 12*T**2)", "d3p": "(24*T - 12)"}


def term(first: str, second: str) -> str:
    return P[first].replace("T", "x") + "*" + P[second].replace("T", "y")


mu = 1.0
shear = f"{mu}*({term('p', 'd2p')} - {term('d2p', 'p')})"
sigma_exact = nd.coefficient([[f"{2 * mu}*{term('dp', 'dp')}", shear],
                              [shear, f"-{2 * mu}*{term('dp', 'dp')}"]])
BODY_FORCE = [f"-{mu}*({term('d2p', 'dp')} + {term('p', 'd3p')})",
              f"{mu}*({term('d3p', 'p')} + {term('dp', 'd2p')})"]
SIDES = ["bottom", "right", "top", "left"]
SQUARE = nd.scene.Geometry(kind="polygon", points=[[0, 0], [1, 0], [1, 1], [0, 1]],
                           labels=SIDES, maxh=0.25)


def primal_stress_error(mesh, nu: float, order: int) -> float:
    """The relative L² stress error of the primal P_order method (displacement form)."""
    scene = nd.Scene(name=f"square-nu{nu}", geometry=SQUARE, boundary={"dirichlet": SIDES},
                     material=nd.scene.Material(E=2 * mu * (1 + nu), nu=nu),
                     loads=nd.scene.Loads(body_force=BODY_FORCE))
    nd.validate(scene)
    sigma_h = nd.solve_primal(scene, mesh=mesh, order=order).sigma
    return nd.l2_norm(sigma_h - sigma_exact, mesh) / nd.l2_norm(sigma_exact, mesh)


mesh = nd.build_mesh(SQUARE, LEVELS[-1])
ratios, primal_errors = {}, {}
for order in (1, 2):
    primal_errors[order] = [primal_stress_error(mesh, nu, order) for nu in NUS]
    errors = primal_errors[order]
    ratios[f"P{order}"] = errors[-1] / errors[0]
    print(f"P{order}: stress error {errors[0]:.3e} (nu = {NUS[0]}), {errors[-1]:.3e} "
          f"(nu = {NUS[-1]}), ratio {ratios[f'P{order}']:.2f}")

fig, ax = plt.subplots(figsize=(6, 4))
lam_over_mu = [2 * nu / (1 - 2 * nu) for nu in NUS]
for order, marker in ((1, "s-"), (2, "o-")):
    ax.loglog(lam_over_mu, primal_errors[order], marker, label=f"P{order}")
ax.set_xlabel(r"$\lambda/\mu$")
ax.set_ylabel(r"relative $L^2$ error of $\sigma$")
ax.set_title(f"Primal methods on the clamped square, level {LEVELS[-1]}")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
lesson.save(fig, "primal_locking")

# %% [markdown]
# ## Exercise 2: how many divergence-free $P_1$ fields are there?
#
# On a triangle with vertices $a_k$ and barycentric gradients $\nabla\varphi_k$, a $P_1$
# field $v = \sum_k v_k\varphi_k$ has the constant divergence
# $\sum_k \nabla\varphi_k \cdot v_k$. Stacking these rows for all $T$ triangles over the
# $2V_{\mathrm{int}}$ unknowns ($v = 0$ on $\partial\Omega$) gives a
# $T \times 2V_{\mathrm{int}}$ matrix $D$; its kernel is the space the $P_1$ solution is
# pushed into as $\lambda \to \infty$. By Euler's formula $T = 2V - V_\partial - 2$ on a
# triangulation of a polygon with $V_\partial$ boundary vertices, so
#
# $$
# 2V_{\mathrm{int}} - T = -V_\partial + 2 < 0 :
# $$
#
# there are more constraints than unknowns, and unless the mesh is special (criss-cross)
# the only divergence-free $P_1$ field is $v = 0$. The $\lambda$-limit of the $P_1$
# solution is $u_h = 0$, whatever $f$: that is locking.

# %%
def boundary_vertices(triangles: np.ndarray) -> set[int]:
    """The vertices on the boundary: those of the edges that only one triangle has."""
    edges = np.sort(triangles[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    return set(unique[count == 1].ravel().tolist())


def divergence_matrix(mesh) -> tuple[np.ndarray, int]:
    """D (T x 2 V_int): elementwise divergence of P1 fields vanishing on the boundary."""
    points, triangles = nd.mesh_arrays(mesh)
    boundary = boundary_vertices(triangles)
    interior = [k for k in range(len(points)) if k not in boundary]
    column = {k: i for i, k in enumerate(interior)}
    D = np.zeros((len(triangles), 2 * len(interior)))
    for t, tri in enumerate(triangles):
        corners = points[tri]
        gradients = np.linalg.inv(np.c_[np.ones(3), corners])[1:].T   # grad phi_k as rows
        for k, g in zip(tri, gradients):
            if k in column:
                D[t, 2 * column[k]: 2 * column[k] + 2] = g
    return D, len(interior)


divergence_free = []
for level in LEVELS:
    square = nd.build_mesh(SQUARE, level)
    D, n_interior = divergence_matrix(square)
    rank = np.linalg.matrix_rank(D)
    row = {"level": level, "T": D.shape[0], "unknowns": D.shape[1],
           "kernel": int(D.shape[1] - rank), "count": int(D.shape[1] - D.shape[0])}
    divergence_free.append(row)
    print(f"level {level}: T = {row['T']:4d}, 2 V_int = {row['unknowns']:4d}, "
          f"2 V_int - T = {row['count']:4d}, divergence-free P1 fields: {row['kernel']}")

# %%
lesson.results({"primal_ratios": ratios, "divergence_free": divergence_free})
