# %% [markdown]
# # Tutorial 1: The PEERS spaces, their unknowns and the discrete inf-sup condition
#
# **Run time** on a 2-core laptop: about 4 s; about 4 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 01 --quick`).
#
# **The idea in words.** In a stress-based method the unknown we solve for is the stress
# itself (the forces per area inside the body), not the displacement. The stress must
# balance the loads (its divergence is the body force), be symmetric (no net torque on a
# small square) and be related to the strain by Hooke's law. The displacement and the
# rotation $\eta$ enter as Lagrange multipliers of the first two requirements. Such a
# "mixed" method is stable only if the stress space is rich enough to answer every
# displacement and rotation it is tested with; the number that measures this is the
# inf-sup constant $\beta_h$. This tutorial counts the unknowns of the PEERS spaces and
# computes $\beta_h$ on a sequence of meshes: bounded away from zero with PEERS, zero
# without its bubble functions.
#
# **Problem.** Plane-strain linear elasticity on a polygon $\Omega$, written for the
# *stress* $\sigma$ as the primary unknown (thesis Ch. 3.1, Hellinger-Reissner form with
# weakly imposed symmetry): find $\sigma$, the displacement $u$ and the rotation
# $\eta = \frac12(\partial_2 u_1 - \partial_1 u_2)$ with
#
# $$
# \begin{aligned}
# \tilde a(\sigma, \tau) + b(u, \tau) + s(\eta, \tau) &= \langle u_D, \tau n\rangle
#   && \forall \tau && (\mathbb{C}^{-1}\sigma = \varepsilon(u) \text{, tested}),\\
# b(v, \sigma) &= -f(v) && \forall v && (\operatorname{div}\sigma = -f),\\
# s(\xi, \sigma) &= 0 && \forall \xi && (\sigma \text{ is symmetric}),
# \end{aligned}
# $$
#
# with $\tilde a(\sigma, \tau) = \int_\Omega \mathbb{C}^{-1}\sigma : \tau\,dx$,
# $b(v, \tau) = \int_\Omega v \cdot \operatorname{div}\tau\,dx$ and
# $s(\xi, \tau) = \int_\Omega \xi\,(\tau_{12} - \tau_{21})\,dx$
# (eqs. (3.12), (3.24), (3.32); the first three rows of (3.62)). The domain is the
# block $[-4,4]\times[-1,1]$ of Example 3.46; for the inf-sup computation it is clamped
# ($u_D = 0$) on all four sides, so that no boundary multipliers enter.
#
# **Discretisation.** The PEERS triple of Arnold, Brezzi and Douglas, eq. (3.61):
# $X_h = RT_0^2 \oplus \operatorname{Curl}(\text{cubic bubbles})^2$ for the two rows of
# $\sigma$, $M_h = P_0^2$ for $u$ and $S_h$ = continuous $P_1$ for $\eta$, on the
# structured triangulations of Table 3.1.
#
# **What you will learn.**
# 1. How many unknowns each PEERS space has, and why (Table 3.1).
# 2. What the discrete inf-sup condition (Lemma 3.28) says, and how to *compute* the
#    inf-sup constant $\beta_h$ on small meshes as a generalised eigenvalue problem.
# 3. Why the Curl bubbles are needed: without them $\beta_h = 0$.
#
# Tutorial 2 takes the same spaces to the incompressible limit $\nu \to \frac12$ (locking).
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011: Sections 3.1-3.2,
# eq. (3.61), Lemma 3.28, Table 3.1. D. N. Arnold, F. Brezzi, J. Douglas Jr., *PEERS:
# a new mixed finite element for plane elasticity*, Japan J. Appl. Math. 1 (1984).
# D. Boffi, F. Brezzi, M. Fortin, *Mixed finite element methods and applications*,
# Springer 2013, Chapter 3 (inf-sup constants as eigenvalues).
#
# Run as a script (`python tutorials/01_peers_spaces.py`) or as a notebook
# (`ngdual tutorials --notebooks DIR`). `NGDUAL_QUICK=1` selects coarse settings.

# %% [markdown]
# ## Parameters
# Quick mode (`NGDUAL_QUICK=1`) keeps every computation to a few seconds. This
# tutorial looks *inside* the discretisation (spaces, matrices): `nd.assemble` builds the
# matrices of a scene on a mesh, `nd.verification.infsup` the norms of the inf-sup test.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("01_peers_spaces")                       # figures and results.json go here
QUICK = lesson.quick
DOF_LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4, 5]     # Table 3.1 rows to reproduce
INF_SUP_LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]       # meshes for the eigenvalue problem

# %% [markdown]
# ## The domain and the mesh
#
# Example 3.46: clamped ends $\Gamma_D$, a loaded top $\Gamma_N$ and a contact part
# $\Gamma_C$ at the bottom (used from Tutorial 3 on). Level 1 is the coarsest mesh of
# Table 3.1; every level halves $h$.

# %%
thesis = nd.load_scene("thesis-3.46-frictionless")
lesson.save(nd.plot_geometry(thesis, level=1), "geometry")

# %% [markdown]
# ## 1. The PEERS spaces and their degrees of freedom
#
# On a triangulation with $V$ vertices, $E$ edges and $T$ triangles:
#
# * $RT_0$ has one dof per edge (the normal flux), and each row of $\sigma$ adds one Curl
#   bubble per triangle, so $\dim X_h = 2(E + T)$;
# * $\dim M_h = 2T$ (a constant vector per triangle) and $\dim S_h = V$.
#
# The structured mesh of Example 3.46 (`nd.build_mesh` of its geometry) reproduces
# Table 3.1 of the thesis:
# 180, 64, 27 on level 1, and each uniform refinement multiplies $T$ by four.

# %%
dof_rows = []
for level in DOF_LEVELS:
    mesh = nd.build_mesh(thesis.geometry, level)
    problem = nd.assemble(thesis, mesh)          # its index sets count the dofs per space
    X = len(problem.sigma)                       # r1, r2 (RT0 rows) and b1, b2 (bubbles)
    M = len(problem.index("u1", "u2"))
    S = len(problem.index("eta"))
    assert (X, M, S) == (2 * (mesh.nedge + mesh.ne), 2 * mesh.ne, mesh.nv)
    dof_rows.append({"level": level, "X": X, "M": M, "S": S})
    print(f"level {level}:  dim X_h = {X:7d}   dim M_h = {M:7d}   dim S_h = {S:6d}")

# %% [markdown]
# ## 2. The discrete inf-sup condition
#
# Lemma 3.28 (from Arnold-Brezzi-Douglas, Lemma 4.4) states that there is $\beta > 0$,
# independent of $h$, with
#
# $$
# \sup_{\tau \in X_h} \frac{b(v, \tau) + s(\xi, \tau)}{\|\tau\|_X}
#   \ge \beta\, \|(v, \xi)\|_{L^2} \qquad \forall (v, \xi) \in M_h \times S_h,
# $$
#
# where $\|\tau\|_X^2 = \|\tau\|^2 + \|\operatorname{div}\tau\|^2$ is the
# $H(\operatorname{div})$ norm. With the Gram matrices $X$ (of the $H(\operatorname{div})$
# inner product on $X_h$) and $Y$ (of $L^2$ on $M_h \times S_h$) and the matrix $B$ of
# $b + s$, the supremum is attained at $\tau = X^{-1}By$, so the best constant is
#
# $$
# \beta_h^2 = \min_y \frac{y^\top B^\top X^{-1} B y}{y^\top Y y},
# $$
#
# the smallest eigenvalue of the pencil $(B^\top X^{-1} B, Y)$: $\beta_h$ is the smallest
# singular value of $B$ in these norms. If $\beta_h$ stays away from zero under refinement
# the triple is stable.
#
# We take Example 3.46 with Dirichlet conditions on all four sides (no boundary
# multipliers) and read $B$ off the assembled system: its block $K[\sigma, (u, \eta)]$ is
# exactly $b + s$. `nd.verification.infsup.gram_matrix` assembles $X$ and $Y$;
# `smallest_singular_values` finds the smallest eigenvalues by shift-invert Lanczos
# (`eigsh`), solving with the saddle-point matrix
# $\begin{pmatrix} X & B \\ B^\top & \sigma_0 Y \end{pmatrix}$ so that $X^{-1}$ never
# becomes dense.

# %%
clamped = nd.load_scene("thesis-3.46-frictionless",
                        ["boundary.dirichlet=['left', 'right', 'bottom', 'top']",
                         "boundary.neumann=[]", "boundary.contact=[]"])
lesson.save(nd.plot_geometry(clamped, level=1, title="Example 3.46 clamped on all sides"),
            "geometry_clamped")

infsup = nd.verification.infsup
inf_sup_rows = []
for level in INF_SUP_LEVELS:
    problem = nd.assemble(clamped, nd.build_mesh(clamped.geometry, level))
    G = infsup.gram_matrix(problem)
    stress, rt0, mult = problem.sigma, problem.index("r1", "r2"), problem.mult
    Y = G[mult][:, mult]
    peers_beta = infsup.smallest_singular_values(G[stress][:, stress],
                                                 problem.block(stress, mult), Y)
    bare_beta = infsup.smallest_singular_values(G[rt0][:, rt0], problem.block(rt0, mult), Y)
    h = np.sqrt(2.0) * 2.0 ** (1 - level)
    inf_sup_rows.append({"level": level, "h": h, "peers": peers_beta.tolist(),
                         "rt0_only": bare_beta.tolist()})
    print(f"level {level}  h = {h:.4f}   PEERS: beta_h = {peers_beta[0]:.4f}   "
          f"RT0 without bubbles: three smallest = {np.array2string(bare_beta, precision=2)}")

# %% [markdown]
# PEERS keeps $\beta_h \approx 0.39$ on every level: the discrete inf-sup condition holds
# with a constant independent of $h$. Without the Curl bubbles two singular values are zero
# (spurious $(u, \eta)$ modes that no stress can "see") and the next one decays like $h$.
# The bubbles are divergence free, so they do not change $b(\cdot,\cdot)$; they enrich the
# antisymmetric part of $\tau$ that $s(\xi, \tau)$ tests, which is exactly what the
# rotation needs.

# %%
fig, ax = plt.subplots(figsize=(6, 4))
hs = [row["h"] for row in inf_sup_rows]
ax.loglog(hs, [row["peers"][0] for row in inf_sup_rows], "o-", label="PEERS: RT₀ + Curl bubbles")
ax.loglog(hs, [row["rt0_only"][2] for row in inf_sup_rows], "s--",
          label="RT₀ alone: 3rd smallest (two are 0)")
ax.set_xlabel("mesh size h")
ax.set_ylabel(r"smallest singular value $\beta_h$")
ax.set_title("Discrete inf-sup constant (Lemma 3.28)")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
lesson.save(fig, "inf_sup")

# %% [markdown]
# Why the bubbles are divergence free: a bubble $b_T$ vanishes on $\partial T$, so
# $\operatorname{Curl} b_T$ has zero normal flux through every edge and
# $\operatorname{div}\operatorname{Curl} b_T = 0$. They leave $b(\cdot,\cdot)$ alone and
# only enrich the antisymmetric part of $\tau$, which $s(\xi, \tau)$ tests.

# %%
lesson.results({"dofs": dof_rows, "inf_sup": inf_sup_rows})

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/01_peers_spaces_solutions.py`.
#
# 1. **The norm matters.** Recompute the smallest *and* the largest singular value of $B$
#    with the $L^2$ norm instead of the $H(\operatorname{div})$ norm on $X_h$ (drop
#    $\|\operatorname{div}\tau\|^2$ from the Gram matrix). Which of the two depends on
#    $h$? Why do Lemma 3.28 and the error analysis work in $\|\cdot\|_X$?
# 2. **Counting.** Use Euler's formula $V - E + T = 1$ to write $\dim X_h$, $\dim M_h$ and
#    $\dim S_h$ of Table 3.1 as functions of the level $k$ of Example 3.46, and check them
#    against `ngdual dofs thesis-3.46-frictionless --levels 1 2 3 4 5 6 7 8`.
