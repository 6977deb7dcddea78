# %% [markdown]
# # Tutorial 2: Locking-free PEERS as ν → ½
#
# **Run time** on a 2-core laptop: about 6 s; about 5 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 02 --quick`).
#
# **The idea in words.** In a nearly incompressible material (rubber, $\nu$ close to ½)
# the volume hardly changes, whatever the load. A displacement method with linear elements
# has too few displacements that keep the volume of every triangle, so it stiffens
# artificially: it "locks", and the computed displacement is far too small. A stress-based
# method does not ask the displacement to keep any volume; its error stays the same as
# $\nu \to \frac12$. The pictures compare the errors of both methods over $\nu$ and the
# stresses they compute.
#
# **Problem.** Plane-strain elasticity on the unit square, clamped ($u = 0$) on the whole
# boundary, with a body force $f$ manufactured from the divergence-free displacement
# $u = \operatorname{Curl}\psi$, $\psi = x^2(1 - x)^2 y^2(1 - y)^2$. Since
# $\operatorname{div} u = 0$, $\sigma = 2\mu\,\varepsilon(u)$ and $f = -\mu\,\Delta u$ do
# not depend on the Lamé constant $\lambda$: the *same* exact solution for every Poisson
# ratio $\nu$ when $\mu$ is fixed. As $\nu \to \frac12$,
# $\lambda/\mu = 2\nu/(1 - 2\nu) \to \infty$ (nearly incompressible material).
#
# **Discretisation.** PEERS (3.61) for $(\sigma, u, \eta)$, the subject of Tutorial 1,
# against the standard primal method with continuous piecewise linear displacements
# ($P_1$), on the same netgen meshes of the square.
#
# **What you will learn.**
# 1. What *locking* is: the $P_1$ errors grow with $\lambda/\mu$ on a fixed mesh; the
#    PEERS errors do not move (the constants of Theorem 3.35 do not depend on $\lambda$).
# 2. How to see it: the $P_1$ stress is polluted by a spurious pressure
#    $\lambda \operatorname{div} u_h$.
# 3. PEERS converges at first order for every $\nu$; $P_1$ at $\nu \approx \frac12$ is far
#    from its asymptotic regime on practical meshes.
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011: Sections 3.1-3.2, eq.
# (3.61), Theorem 3.35. D. N. Arnold, F. Brezzi, J. Douglas Jr., *PEERS: a new mixed
# finite element for plane elasticity*, Japan J. Appl. Math. 1 (1984). I. Babuška,
# M. Suri, *Locking effects in the finite element approximation of elasticity
# problems*, Numer. Math. 62 (1992).

# %% [markdown]
# ## Parameters

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("02_locking")                            # figures and results.json go here
QUICK = lesson.quick
LOCKING_LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]       # refinements of the square mesh
NUS = [0.3, 0.45, 0.49, 0.499, 0.4999]                   # Poisson ratios of the sweep
SHEAR_MODULUS = 1.0                                      # μ is kept fixed while ν -> 1/2
MAXH = 0.25                                              # netgen mesh size of level 1

# %% [markdown]
# ## 1. The manufactured solution
#
# On the unit square with $u = 0$ on the whole boundary we manufacture a divergence-free
# displacement
#
# $$
# u = \operatorname{Curl}\psi = (\partial_2\psi, -\partial_1\psi), \qquad
# \psi = p(x)\,p(y), \qquad p(t) = t^2(1 - t)^2 .
# $$
#
# Since $\operatorname{div} u = 0$, $\sigma = 2\mu\,\varepsilon(u)$ and
# $f = -\operatorname{div}\sigma = -\mu\,\Delta u$ do not depend on $\lambda$: the same
# exact solution for every $\nu$ when $\mu$ is fixed. A robust method must give the same
# errors for $\nu = 0.3$ and $\nu = 0.4999$ ($\lambda/\mu \approx 5000$).
#
# The primal competitor is the standard $P_1$ method, `nd.solve_primal(scene, mesh=mesh)`:
# find continuous piecewise linear $u_h$, zero on the boundary, with
#
# $$
# \int_\Omega 2\mu\,\varepsilon(u_h) : \varepsilon(v)
#   + \lambda \operatorname{div} u_h \operatorname{div} v \,dx = \int_\Omega f \cdot v \,dx
#   \qquad \forall v .
# $$
#
# As $\lambda \to \infty$ the term $\lambda \operatorname{div} u_h \operatorname{div} v$
# forces $\operatorname{div} u_h \approx 0$, which continuous $P_1$ fields can barely
# satisfy: the method *locks*.
#
# The formulas below are scene expressions in `x` and `y` (see `nd.Expression`);
# `nd.coefficient` turns a vector or a matrix of them into an NGSolve field, and
# `nd.l2_norm` measures a field, or its error, in $L^2(\Omega)$.

# %%
P = {"p": "(T**2*(1 - T)**2)", "dp": "(2*T - 6*T**2 + 4*T**3)",
     "d2p": "(2 - 12*T + 12*T**2)", "d3p": "(24*T - 12)"}


def term(first: str, second: str) -> str:
    """The product first(x) * second(y) of derivatives of p."""
    return P[first].replace("T", "x") + "*" + P[second].replace("T", "y")


mu = SHEAR_MODULUS
EXACT_U = [term("p", "dp"), f"-{term('dp', 'p')}"]
shear = f"{mu}*({term('p', 'd2p')} - {term('d2p', 'p')})"
EXACT_SIGMA = [[f"{2 * mu}*{term('dp', 'dp')}", shear], [shear, f"-{2 * mu}*{term('dp', 'dp')}"]]
BODY_FORCE = [f"-{mu}*({term('d2p', 'dp')} + {term('p', 'd3p')})",
              f"{mu}*({term('d3p', 'p')} + {term('dp', 'd2p')})"]
SIDES = ["bottom", "right", "top", "left"]


u_exact, sigma_exact = nd.coefficient(EXACT_U), nd.coefficient(EXACT_SIGMA)


def square_scene(nu: float) -> nd.Scene:
    """The unit square, clamped everywhere, with E chosen so that μ stays fixed."""
    scene = nd.Scene(name=f"square-nu{nu}",
                     geometry=nd.scene.Geometry(kind="polygon",
                                                points=[[0, 0], [1, 0], [1, 1], [0, 1]],
                                                labels=SIDES, maxh=MAXH),
                     boundary={"dirichlet": SIDES},
                     material=nd.scene.Material(E=2 * mu * (1 + nu), nu=nu),
                     loads=nd.scene.Loads(body_force=BODY_FORCE))
    nd.validate(scene)
    return scene


lesson.save(nd.plot_geometry(square_scene(NUS[0]), level=LOCKING_LEVELS[-1],
                             title=f"Unit square, clamped, level {LOCKING_LEVELS[-1]}"),
            "geometry")


def relative_l2(field, exact, mesh) -> float:
    """||exact - field|| / ||exact|| in L²(Ω)."""
    return nd.l2_norm(exact - field, mesh) / nd.l2_norm(exact, mesh)


def errors(nu: float, level: int) -> dict:
    """Relative L² errors of u and σ for PEERS and P1 on the same mesh."""
    scene = square_scene(nu)
    solution = nd.solve(scene, level)
    mesh = solution.problem.fes.mesh
    f = nd.fields(solution)
    p1 = nd.solve_primal(scene, mesh=mesh)             # u_h in P1 and σ_h = C ε(u_h)
    return {"nu": nu, "level": level, "triangles": mesh.ne,
            "peers_u": relative_l2(f.u, u_exact, mesh),
            "peers_sigma": relative_l2(f.sigma, sigma_exact, mesh),
            "p1_u": relative_l2(p1.u, u_exact, mesh),
            "p1_sigma": relative_l2(p1.sigma, sigma_exact, mesh)}


# %% [markdown]
# ## 2. The sweep $\nu \to \frac12$ on a fixed mesh

# %%
print(f"{'nu':>7} {'PEERS u':>9} {'PEERS σ':>9} {'P1 u':>9} {'P1 σ':>9}   "
      f"(relative L² errors, level {LOCKING_LEVELS[-1]})")
sweep = [errors(nu, LOCKING_LEVELS[-1]) for nu in NUS]
for row in sweep:
    print(f"{row['nu']:7.4f} {row['peers_u']:9.3e} {row['peers_sigma']:9.3e} "
          f"{row['p1_u']:9.3e} {row['p1_sigma']:9.3e}")

# %% [markdown]
# PEERS errors do not move as $\nu \to \frac12$; the $P_1$ errors grow with
# $\lambda/\mu$. The ratio of the errors at $\nu = 0.4999$ and $\nu = 0.3$ condenses this
# into one number per method:

# %%
first, last = sweep[0], sweep[-1]
ratios = {key: last[key] / first[key] for key in ("peers_u", "peers_sigma", "p1_u", "p1_sigma")}
for key, value in ratios.items():
    print(f"error(nu = {last['nu']}) / error(nu = {first['nu']}) for {key:11s}: {value:8.2f}")

fig, ax = plt.subplots(figsize=(6, 4))
lam_over_mu = [nd.scene.Material(2 * mu * (1 + nu), nu).lame[0] / mu for nu in NUS]
for key, style, label in (("peers_sigma", "o-", "PEERS σ"), ("peers_u", "o--", "PEERS u"),
                          ("p1_sigma", "s-", "P1 σ"), ("p1_u", "s--", "P1 u")):
    ax.loglog(lam_over_mu, [row[key] for row in sweep], style, label=label)
ax.set_xlabel(r"$\lambda/\mu$")
ax.set_ylabel("relative $L^2$ error")
ax.set_title(f"Locking on the unit square, level {LOCKING_LEVELS[-1]}")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
lesson.save(fig, "locking")

# %% [markdown]
# ## 3. Under refinement
#
# Refining the mesh: PEERS converges at first order (Theorem 3.35) for both $\nu$; $P_1$
# at $\nu = 0.4999$ is far from its asymptotic regime on these meshes.

# %%
convergence = [errors(nu, level) for nu in (NUS[0], NUS[-1]) for level in LOCKING_LEVELS]
print(f"{'nu':>7} {'level':>5} {'triangles':>9} {'PEERS σ':>9} {'P1 σ':>9}")
for row in convergence:
    print(f"{row['nu']:7.4f} {row['level']:5d} {row['triangles']:9d} "
          f"{row['peers_sigma']:9.3e} {row['p1_sigma']:9.3e}")

# %% [markdown]
# ## 4. What locking looks like
#
# The von Mises stress at $\nu = 0.4999$ on the finest mesh, exact, PEERS and $P_1$, on
# one colour scale (the exact maximum). PEERS reproduces the picture. $P_1$ is *locked*:
# the constraint $\operatorname{div} u_h \approx 0$ leaves almost no admissible $P_1$
# fields (Exercise 2), so $u_h$ is far too small, and so is the deviatoric stress that
# von Mises measures.

# %%
nu_max, level_max = NUS[-1], LOCKING_LEVELS[-1]
incompressible = nd.solve(square_scene(nu_max), level_max)
mesh = incompressible.problem.fes.mesh
p1_sigma = nd.solve_primal(square_scene(nu_max), mesh=mesh).sigma
peers_sigma = nd.fields(incompressible).sigma
top = float(np.max(nd.post.element_values(mesh, nd.post.von_mises(sigma_exact, nu_max))[2]))
for name, field in (("exact", sigma_exact), ("PEERS", peers_sigma), ("P1", p1_sigma)):
    lesson.save(nd.plot_von_mises(mesh, field, nu_max, f"{name}: von Mises stress, "
                                  f"ν = {nu_max}, level {level_max}", vmax=top),
                f"von_mises_{name.lower()}")

# %% [markdown]
# Where the large $P_1$ stress *error* of Section 2 sits: in the mean stress
# $p = (\sigma_{11} + \sigma_{22})/2$, which is zero for the exact solution
# ($\sigma_{22} = -\sigma_{11}$). For $P_1$ it is $(\mu + \lambda)\operatorname{div} u_h$:
# a tiny divergence times $\lambda = 5000\mu$, oscillating from triangle to triangle. For
# PEERS $p_h$ is as small as its discretisation error.

# %%
mean_stress = {}
points, triangles = nd.mesh_arrays(mesh)
for name, field in (("PEERS", peers_sigma), ("P1", p1_sigma)):
    mean_stress[name] = nd.post.element_values(mesh, 0.5 * (field[0, 0] + field[1, 1]))[2]
scale = float(np.max(np.abs(mean_stress["P1"])))
fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
for ax, (name, values) in zip(axes, mean_stress.items()):
    art = ax.tripcolor(points[:, 0], points[:, 1], triangles, facecolors=values,
                       cmap="RdBu_r", vmin=-scale, vmax=scale, edgecolors="none")
    ax.set_aspect("equal")
    ax.set_xlabel("$x_1$")
    ax.set_ylabel("$x_2$")
    ax.set_title(f"{name}: max |p_h| = {np.max(np.abs(values)):.2g}")
fig.colorbar(art, ax=axes, label="mean stress $p_h = (\\sigma_{11} + \\sigma_{22})/2$ "
             "(exact: 0)")
fig.suptitle(f"Mean stress at ν = {nu_max}, level {level_max}, one colour scale")
lesson.save(fig, "mean_stress")
mean_stress_max = {name: float(np.max(np.abs(v))) for name, v in mean_stress.items()}

# %% [markdown]
# In a notebook, NGSolve's webgui shows the PEERS stress to turn and zoom; a script
# points to its picture above, `von_mises_peers.png`.

# %%
lesson.draw(nd.post.von_mises(peers_sigma, nu_max), mesh, "von_mises_peers")

# %%
lesson.results({"locking_sweep": sweep, "convergence": convergence, "ratios": ratios,
                "mean_stress_max": mean_stress_max})

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/02_locking_solutions.py`.
#
# 1. **Higher order does not cure locking by itself.** Replace the $P_1$ method by $P_2$
#    (`nd.solve_primal(scene, mesh=mesh, order=2)`). Compute the error ratio between
#    $\nu = 0.4999$ and $\nu = 0.3$ for the stress. Is $P_2$ locking-free on these meshes?
# 2. **Counting divergence-free fields.** As $\lambda \to \infty$ the $P_1$ solution is
#    driven into the subspace
#    $\{v_h \in P_1 : v_h = 0 \text{ on } \partial\Omega,\ \operatorname{div} v_h = 0
#    \text{ on every triangle}\}$. Assemble the matrix that maps the $2V_{\mathrm{int}}$
#    nodal values to the $T$ elementwise divergences and compute the dimension of its
#    kernel on the meshes of this tutorial. Compare with the count $2V_{\mathrm{int}} - T$.
#    What does the answer say about the $P_1$ solution at $\nu \to \frac12$?
