# %% [markdown]
# # Solutions to Tutorial 6: The a posteriori error estimator of Chapter 4
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("06_estimator_solutions")
QUICK = lesson.quick
LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4]

# %% [markdown]
# ## Exercise 1: the patch test
#
# For $u = Gx + c$ the stress $\sigma = \mathbb{C}\,\varepsilon(u)$ is constant and the
# rotation $\eta = (G_{12} - G_{21})/2$ is constant: both lie in the PEERS spaces, and the
# discrete solution reproduces them. Then $w_h = \mathbb{C}^{-1}\sigma_h + \eta_h = G$
# exactly, and every residual of (4.15) vanishes: $f + \operatorname{div}\sigma_h = 0$,
# $\operatorname{as}(\sigma_h) = 0$, $\operatorname{curl} G = 0$, no jumps,
# $w_h t = \partial_t u_D$ on $\Gamma_D$, $\sigma n = t_0$ on $\Gamma_N$.
# $\eta_{u,T}$ cannot vanish: $u_h$ is piecewise *constant* and cannot represent an
# affine $u$. $h_T\|w_h\|_T$ measures exactly this $O(h)$ error of $u_h$, and the trace
# terms compare $u_h$ on the boundary elements with $u_D$ and $\varphi$.

# %%
E, NU = 100.0, 0.3
PENTAGON = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 2.0), (0.0, 1.0)]
SIDES = ["bottom", "right", "roof_right", "roof_left", "left"]
g = [[0.3, -0.2], [0.5, 0.1]]                              # not symmetric: eta = -0.35
G = np.array(g)
lam, mu = nd.scene.Material(E, NU).lame
strain = 0.5 * (G + G.T)
stress = 2 * mu * strain + lam * np.trace(strain) * np.eye(2)
traction = stress @ np.array([1.0, 1.0]) / np.sqrt(2)   # sigma n on roof_right
affine = nd.Scene(name="affine-patch-test",
               geometry=nd.scene.Geometry(kind="polygon", points=PENTAGON, labels=SIDES, maxh=0.5),
               boundary={"dirichlet": ["bottom", "right", "roof_left", "left"],
                         "neumann": ["roof_right"]},
               material=nd.scene.Material(E, NU),
               loads=nd.scene.Loads(traction=[repr(float(t)) for t in traction],
                           displacement=[f"{g[0][0]!r}*x + {g[0][1]!r}*y + 0.1",
                                         f"{g[1][0]!r}*x + {g[1][1]!r}*y - 0.2"]))
nd.validate(affine)
# the terms of eta_sigma (4.15) and those of the displacement part, by their names in
# nd.estimate(...).summed()
SIGMA_TERMS = ("residual", "asymmetry", "curl", "jump_interior", "jump_dirichlet",
               "jump_neumann", "jump_contact")
U_TERMS = ("u_volume", "u_dirichlet", "u_neumann", "u_contact")
patch = nd.estimate(nd.solve(affine, 1)).summed()
sigma_part = sum(patch[k] for k in (*SIGMA_TERMS, "neumann"))
u_part = sum(patch[k] for k in U_TERMS)
print(f"sigma terms and neumann: {sigma_part:.1e};  u terms: {u_part:.2e}")
print({k: f"{v:.1e}" for k, v in patch.items()})

# %% [markdown]
# ## Exercise 2: Table 4.2
#
# $\eta_{as,T} = \|\operatorname{as}(\sigma_h)\|_T$ ($L^2$) or
# $\|\operatorname{as}(\sigma_h)\|_{H(\operatorname{div},T)}$. The maximum sits in the
# lower corners, where $\Gamma_D$ meets $\Gamma_C$: $\sigma$ is singular there and PEERS
# approximates its symmetry poorly. In $L^2$ the maximum stays about constant, in
# $H(\operatorname{div})$ it grows: the $\nabla a$ part is not weighted with $h$. The
# share $q_{as}$ of triangles near the maximum shrinks with $h$: the large indicators
# concentrate in the corners.

# %%
thesis = nd.load_scene("thesis-3.46-coulomb")
table_4_2 = []
for level in LEVELS:
    solution = nd.solve(thesis, level)
    points, triangles = nd.mesh_arrays(solution.problem.fes.mesh)
    centroids = points[triangles].mean(axis=1)                 # one row per triangle
    row = {"level": level}
    for norm in ("l2", "hdiv"):
        eta_as = np.sqrt(nd.estimate(solution, asymmetry=norm).terms["asymmetry"])
        where = centroids[np.argmax(eta_as)]
        row[norm] = {"max": float(eta_as.max()),
                     "q_as": float(np.mean(eta_as >= 0.1 * eta_as.max())),
                     "argmax_xy": [float(where[0]), float(where[1])]}
    table_4_2.append(row)
    print(f"level {level}: L2 max {row['l2']['max']:9.3e} q_as {row['l2']['q_as']:.3f} at "
          f"{np.round(row['l2']['argmax_xy'], 2)};  H(div) max {row['hdiv']['max']:9.3e} "
          f"q_as {row['hdiv']['q_as']:.3f} at {np.round(row['hdiv']['argmax_xy'], 2)}")

# %%
fig, ax = plt.subplots(figsize=(6.5, 4.2))
for norm, label, style in (("l2", r"$L^2$ (ngdual's default)", "o-"),
                           ("hdiv", r"$H(\mathrm{div})$ as printed in (4.15)", "s--")):
    ax.semilogy(LEVELS, [row[norm]["max"] for row in table_4_2], style, label=label)
ax.set_xticks(LEVELS)
ax.set_xlabel("mesh level (uniform refinement)")
ax.set_ylabel(r"$\eta_{as}^{\max} = \max_T \eta_{as,T}$")
ax.set_title("Exercise 2 (Table 4.2): the largest asymmetry indicator,\n"
             "attained in a lower corner where $\\Gamma_D$ meets $\\Gamma_C$")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
lesson.save(fig, "table_4_2")

# %% [markdown]
# ## Exercise 3: $\sum_T \eta_T$ against $(\sum_T \eta_T^2)^{1/2}$
#
# By Cauchy-Schwarz
#
# $$
# \sum_T \eta_T \le \sqrt{N_T}\,\Bigl(\sum_T \eta_T^2\Bigr)^{1/2},
# $$
#
# with near equality when the indicators are about equal. For the smooth square
# ($u = \operatorname{Curl}\psi$, $\psi = x^2(1-x)^2y^2(1-y)^2$, clamped, the problem of
# Tutorial 2) they are, and under uniform refinement the ratio grows like $\sqrt{N_T}$, by
# 2 per level: an effectivity index built on $\sum_T \eta_T$ doubles per level even though
# $\eta/e$ is constant. Theorem 4.8 is a reliability statement; the $\ell^2$ sum
# $(\sum_T \eta_T^2)^{1/2}$ is what is comparable with the error. In Example 3.46 a few
# corner elements carry most of $\eta$ ($\sigma$ is singular there, and $\eta$ itself stops
# decreasing), so the ratio grows more slowly, far below $\sqrt{N_T}$: the indicators are
# not equidistributed, which is what adaptive refinement is for (Tutorial 7).

# %%
P = {"p": "(T**2*(1 - T)**2)", "dp": "(2*T - 6*T**2 + 4*T**3)",
     "d2p": "(2 - 12*T + 12*T**2)", "d3p": "(24*T - 12)"}


def term(first: str, second: str) -> str:
    return P[first].replace("T", "x") + "*" + P[second].replace("T", "y")


shear_modulus = nd.scene.Material(E, NU).lame[1]
square = nd.Scene(name="clamped-square",
               geometry=nd.scene.Geometry(kind="polygon", points=[(0, 0), (1, 0), (1, 1), (0, 1)],
                                 labels=["bottom", "right", "top", "left"], maxh=0.25),
               boundary={"dirichlet": ["bottom", "right", "top", "left"]},
               material=nd.scene.Material(E, NU),
               loads=nd.scene.Loads(body_force=[f"-{shear_modulus}*({term('d2p', 'dp')} + "
                                       f"{term('p', 'd3p')})",
                                       f"{shear_modulus}*({term('d3p', 'p')} + "
                                       f"{term('dp', 'd2p')})"]))
nd.validate(square)
frictionless = nd.load_scene("thesis-3.46-frictionless")
ratios = {"square": [], "thesis": []}
for level in LEVELS:
    for name, scene in (("square", square), ("thesis", frictionless)):
        estimated = nd.estimate(nd.solve(scene, level))
        ratios[name].append({"level": level, "elements": len(estimated.indicators),
                             "ratio": estimated.total_sum / estimated.total,
                             "eta": estimated.total})
    square_row, thesis_row = ratios["square"][-1], ratios["thesis"][-1]
    print(f"level {level}: sum / sqrt(sum of squares) = {square_row['ratio']:7.2f} "
          f"(square, sqrt(N_T) = {np.sqrt(square_row['elements']):6.2f}), "
          f"{thesis_row['ratio']:7.2f} (Example 3.46, sqrt(N_T) = "
          f"{np.sqrt(thesis_row['elements']):6.2f}, eta = {thesis_row['eta']:.1f})")

# %%
fig, ax = plt.subplots(figsize=(6.5, 4.2))
for name, label, style in (("square", "smooth clamped square (Tutorial 2)", "o-"),
                           ("thesis", "Example 3.46, frictionless", "s-")):
    rows = ratios[name]
    ax.loglog([row["elements"] for row in rows], [row["ratio"] for row in rows], style,
              label=label)
elements = sorted({row["elements"] for rows in ratios.values() for row in rows})
ax.loglog(elements, np.sqrt(elements), "k:", label=r"Cauchy-Schwarz bound $\sqrt{N_T}$")
ax.set_xlabel(r"number of triangles $N_T$")
ax.set_ylabel(r"$\sum_T \eta_{tot,T} \,/\, (\sum_T \eta_{tot,T}^2)^{1/2}$")
ax.set_title("Exercise 3: sum against square root of the sum of squares")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
lesson.save(fig, "sum_ratios")

# %%
lesson.results({"patch_sigma": sigma_part, "patch_u": u_part, "table_4_2": table_4_2,
                "sum_ratios": ratios})
