# %% [markdown]
# # Tutorial 6: The a posteriori error estimator of Chapter 4
#
# **Problem.** Given a discrete solution
# $(\sigma_h, \nu_h; u_h, \eta_h, \varphi_h, \lambda_t, \lambda_n)$ of (3.62), how large is
# its error, and *where* is it made? Theorem 4.8 bounds the error in
# $X \times H^{-1/2}(A_C) \times \tilde Y$ by computable local quantities,
#
# \begin{equation*}
# \|\text{error}\| \le C \sum_T \eta_{tot,T}, \qquad
# \eta_{tot,T}^2 = \eta_{\sigma,T}^2 + \eta_{u,T}^2 + \eta_{\mathcal{F},T}^2 + \eta_{N,T}^2
# \tag{4.50}
# \end{equation*}
#
# (with (4.49)), with $\eta_{\sigma,T}$ of (4.15) (residuals of the stress equations),
# $\eta_{u,T}$ of (4.31) (residuals of the displacement), the friction term
# $\hat h\,\|\sigma_t - \mathcal{F}\nu\|^2$ on $A_C$ and the Neumann term
# $\log(1 + \tilde C_N)\,\tilde h\,\|\sigma n - t_0\|^2$ on $\Gamma_N$.
#
# **Discretisation.** PEERS (3.61) on the fine mesh, $P_1$ multipliers on the coarse
# boundary meshes. The indicators are element and edge integrals of the discrete fields;
# $w_h = \mathbb{C}^{-1}\sigma_h + \eta_h$ (the rotation as a skew tensor) approximates
# $\nabla u$.
#
# **What you will learn.**
# 1. Every term of (4.50): what residual it measures, and where on the mesh it lives
#    (Example 3.46 with Coulomb friction: corners, $\Gamma_N$, the ends of $\Gamma_C$,
#    $A_C$).
# 2. `ngdual.estimator.estimate` returns one array per term and element (an
#    `Estimate`); how to sum, split and plot it.
# 3. The *effectivity index* $\eta/e$ on a smooth problem with known solution: it stays
#    in a narrow band, and $\eta$ decreases at the rate of the error.
# 4. Why ngdual measures the asymmetry $\operatorname{as}(\sigma_h)$ in $L^2$ and not in
#    $H(\operatorname{div})$ as printed in (4.15): for PEERS
#    $\|\operatorname{div}\operatorname{as}(\sigma_h)\|$ does not tend to zero
#    (cf. Table 4.2).
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011:
# Chapter 4: eqs. (4.15), (4.31), (4.49)-(4.50),
# Theorems 4.2 and 4.8, Table 4.2. C. Carstensen, G. Dolzmann, *A posteriori error
# estimates for mixed FEM in elasticity*, Numer. Math. 81 (1998). G. N. Gatica, L. F.
# Gatica, E. P. Stephan, *A dual-mixed finite element method for nonlinear incompressible
# elasticity with mixed boundary conditions*, CMAME 196 (2007). R. Verfürth, *A posteriori
# error estimation techniques for finite element methods* (2013).

# %% [markdown]
# ## Parameters

# %%
import math

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import ngsolve as ngs
import numpy as np
from matplotlib.colors import LogNorm

import ngdual as nd
from ngdual.estimator import OTHER_TERMS, SIGMA_TERMS, TERMS, U_TERMS
from ngdual.expr import Expression
from ngdual.rates import observed_rates
from ngdual.scene import Geometry, Loads, Material
from ngdual.studies.tutorials import (
    draw,
    output_dir,
    plot_geometry,
    quick_mode,
    save_figure,
    save_results,
)

QUICK = quick_mode()
THESIS_LEVEL = 3 if QUICK else 4              # Example 3.46 for the pictures of every term
LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4, 5]   # uniform levels of the smooth problem
E, NU, MAXH = 100.0, 0.3, 0.4                 # material and mesh size of the smooth problem
OUT = output_dir("06_estimator")
print(f"quick mode: {QUICK}; output in {OUT}")

# %% [markdown]
# ## 1. The terms of (4.50)
#
# With $t$ the unit tangent, $[\cdot]$ the jump across an interior edge, $u_\Gamma$ the
# value of the piecewise constant $u_h$ at a boundary edge and $\tilde h_e$ the coarse
# edge holding $e$:
#
# * `residual`: $\|f + \operatorname{div}\sigma_h\|_T^2$, the equilibrium
#   $\operatorname{div}\sigma = -f$;
# * `asymmetry`: $\|\operatorname{as}(\sigma_h)\|_T^2$, the symmetry of $\sigma$ (see
#   Section 5);
# * `curl`: $h_T^2\,\|\operatorname{curl} w_h\|_T^2$, $w_h = \nabla u$ is a gradient;
# * `jump_interior`: $\sum_e h_e\,\|[w_h t]\|_e^2$, the tangential continuity of $\nabla u$;
# * `jump_dirichlet`: $\sum_e h_e\,\|w_h t - \partial_t u_D\|_e^2$, $u = u_D$ on $\Gamma_D$;
# * `jump_neumann`: $\sum_e h_e\,\|w_h t + \partial_t\varphi\|_e^2$, $\varphi = -u$ on
#   $\Gamma_N$;
# * `jump_contact`:
#   $\sum_e h_e\,\|w_h t + \partial_t\lambda_t\,t + \partial_t(\lambda_n - g)\,n\|_e^2$,
#   $\lambda = -u$ on $\Gamma_C$ ($\lambda_n - g = -u_n$);
# * `u_volume`: $h_T^2\,\|w_h\|_T^2$, (4.31): $u_h$ against $\nabla u$;
# * `u_dirichlet`, `u_neumann`, `u_contact`: $\sum_e h_e\,\|\dots\|_e^2$, the same traces
#   for $u_\Gamma$ itself;
# * `friction`: $\sum_e \tilde h_e\,\|\sigma_t - \mathcal{F}\nu\|_e^2$ on $A_C$, $(3.62)_5$
#   pointwise;
# * `neumann`: $\log(1+\tilde C_N)\sum_e \tilde h_e\,\|\sigma n - t_0\|_e^2$, the traction
#   $t_0$ on $\Gamma_N$.
#
# The first seven make $\eta_{\sigma,T}$ (4.15), the next four $\eta_{u,T}$ (4.31). Every
# array of an `Estimate` holds the *squared* contribution per element, so
# $\eta_{tot,T}^2$ is their sum.

# %%
print("sigma terms (4.15):", SIGMA_TERMS)
print("u terms (4.31):    ", U_TERMS)
print("others of (4.50):  ", OTHER_TERMS)

# %% [markdown]
# ## 2. Every term on Example 3.46 with Coulomb friction
#
# One solve, one call of `estimate`. The squared terms summed over the mesh show which
# of them dominate $\eta$; the pictures show where.

# %%
thesis = nd.load_scene("thesis-3.46-coulomb")
save_figure(plot_geometry(thesis, level=THESIS_LEVEL,
                          title=f"Example 3.46, Coulomb friction: boundary parts, "
                                f"level {THESIS_LEVEL}"),
            OUT / "geometry.png")
solution = nd.solve(thesis, THESIS_LEVEL)
est = nd.estimate(solution)
mesh = solution.problem.fes.mesh
summed = est.summed()
print(f"level {THESIS_LEVEL}: {mesh.ne} triangles, eta = {est.total:.4e}, "
      f"estimated in {est.seconds:.2f} s")
for name, value in sorted(summed.items(), key=lambda item: -item[1]):
    print(f"  {name:15s} {math.sqrt(value):10.3e}   ({100 * value / est.total**2:5.1f} % of eta^2)")
assert np.allclose(est.eta**2, sum(est.terms.values()))


# %% [markdown]
# Two observations. `residual` vanishes: $f = 0$ is piecewise constant, and
# $\operatorname{div}\sigma_h = -\Pi_0 f$ holds exactly in PEERS (the second row of
# (3.62)). And $\eta$ mixes units: the terms in $\sigma$ (`asymmetry`, `friction`,
# `neumann`) are stresses, of the size of $t_0 \approx 800$, while the terms in
# $w_h \approx \nabla u$ are strains, about $E \approx 2\cdot 10^5$ times smaller. The
# stress terms decide where $\eta$ is large, as the thesis observed for Figs. 4.1-4.8. The
# pictures use one logarithmic colour scale per term; white elements have a zero (or
# round-off) indicator.

# %%
def mesh_arrays(mesh: ngs.Mesh) -> mtri.Triangulation:
    """The NGSolve mesh as a matplotlib triangulation (triangles in element order)."""
    points = np.array([v.point for v in mesh.vertices])
    triangles = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngs.VOL)])
    return mtri.Triangulation(points[:, 0], points[:, 1], triangles)


def plot_terms(mesh, terms: dict, path, title: str, columns: int = 2) -> None:
    """One tripcolor panel per (squared) indicator term, log colour scale, zeros blank."""
    tri = mesh_arrays(mesh)
    width = np.ptp(tri.x) / np.ptp(tri.y)
    rows = math.ceil(len(terms) / columns)
    largest = max(float(np.max(values)) for values in terms.values())
    fig, axes = plt.subplots(rows, columns, figsize=(6.5 * columns, 6.5 * rows / width + 1.2),
                             squeeze=False)
    for ax, (name, values) in zip(axes.flat, terms.items()):
        positive = values[values > 0]
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.triplot(tri, color="0.85", lw=0.2)
        if positive.size == 0 or positive.max() <= 1e-12 * largest:
            ax.set_title(f"{name}: zero up to round-off", fontsize=9)
            continue
        top = positive.max()
        masked = np.ma.masked_less_equal(values, 1e-8 * top)
        art = ax.tripcolor(tri, facecolors=masked, norm=LogNorm(1e-8 * top, top),
                           cmap="viridis", edgecolors="none")
        fig.colorbar(art, ax=ax, fraction=0.03, pad=0.01)
        ax.set_title(f"{name}: sum {np.sum(values):.2e}", fontsize=9)
    for ax in list(axes.flat)[len(terms):]:
        ax.axis("off")
    fig.suptitle(title)
    fig.tight_layout()
    save_figure(fig, path)


plot_terms(mesh, {"eta_tot^2": est.eta**2, **est.terms}, OUT / "terms_thesis_coulomb.png",
           f"Squared indicators of (4.50), Example 3.46, mu_f = 0.5, level {THESIS_LEVEL}")
eta_gf = ngs.GridFunction(ngs.L2(mesh, order=0))
eta_gf.vec.FV().NumPy()[:] = est.eta
draw(eta_gf, mesh, "eta_tot")

# %% [markdown]
# What the pictures show (compare the discussion of Figs. 4.1-4.8):
#
# * `asymmetry`, `curl` and the jumps peak in the corners, where the boundary
#   conditions change and $\sigma$ is singular. `asymmetry` is largest in the two lower
#   corners, where $\Gamma_D$ meets $\Gamma_C$ (Table 4.2). There
#   $\lambda_n \in C_{\tilde h}$ must vanish, i.e. $u_n = g = 0.01$, while $u = 0$ on
#   $\Gamma_D$: the data jump, $\sigma \sim 1/r$ is not square integrable, and these
#   indicators do not decrease under refinement (Exercise 3, Tutorial 7).
# * `neumann` and `jump_neumann` live on the elements at $\Gamma_N$, largest where the
#   traction $t_0$ switches off ($x_1 = \pm 2$) and at the ends of $\Gamma_N$.
# * `friction` lives on the elements along $\Gamma_C$ ($A_C = \operatorname{supp}\mathcal{F}$),
#   where it measures how far the pointwise $\sigma_t$ is from $\mathcal{F}\nu$:
#   $(3.62)_5$ holds only tested with the hats.
# * `jump_contact` and `u_contact` live on $\Gamma_C$ too, the former largest at the ends
#   of $\Gamma_C$, where $\lambda_n$ must vanish ($C_{\tilde h}$ of (3.61)) while the body
#   hangs above the gap.
#
# ## 3. A smooth problem with a known solution
#
# To measure the effectivity index $\eta/e$ we need the exact error $e$. The manufactured
# problem of `tests/test_manufactured_convergence.py`: the convex pentagon with corners
# $(0,0)$, $(2,0)$, $(2,1)$, $(1,2)$, $(0,1)$, Neumann side from $(2,1)$ to $(1,2)$,
# Dirichlet elsewhere, and the polynomial displacement
#
# $$
# u = \operatorname{Curl}\psi + w/\lambda, \qquad
# \psi = |x - p_1|^2\,|x - p_2|^2, \qquad
# w = (x^2 - 3x + y^2 - 3y + 4,\ x^2 + xy - 3x),
# $$
#
# $p_1 = (2,1)$, $p_2 = (1,2)$: $u$, $\sigma$, $f$ and $t_0$ are polynomials, $u$
# vanishes at the ends of $\Gamma_N$. A few lines of exact polynomial arithmetic (2-D
# NumPy coefficient arrays `c[i, j]` of $x^i y^j$) produce the scene formulas.

# %%
P2 = np.polynomial.polynomial


def poly(terms: dict) -> np.ndarray:
    """{(i, j): c} -> coefficient array of sum c x^i y^j."""
    out = np.zeros((5, 5))
    for (i, j), c in terms.items():
        out[i, j] = c
    return out


def pad(a: np.ndarray, shape=(9, 9)) -> np.ndarray:
    out = np.zeros(shape)
    out[:a.shape[0], :a.shape[1]] = a
    return out


def mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.zeros((a.shape[0] + b.shape[0] - 1, a.shape[1] + b.shape[1] - 1))
    for (i, j), c in np.ndenumerate(a):
        out[i:i + b.shape[0], j:j + b.shape[1]] += c * b
    return pad(out[:9, :9])


def dx(a):
    return pad(P2.polyder(a, axis=0))


def dy(a):
    return pad(P2.polyder(a, axis=1))


def text(a: np.ndarray) -> str:
    """A scene formula in x, y (see ngdual.expr)."""
    terms = (f"({float(c)!r})*x**{i}*y**{j}" for (i, j), c in np.ndenumerate(a) if c)
    return " + ".join(terms) or "0"


POINTS = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 2.0), (0.0, 1.0)]
SIDES = ["bottom", "right", "roof_right", "roof_left", "left"]
lam, mu = Material(E, NU).lame
q1 = pad(poly({(2, 0): 1, (1, 0): -4, (0, 2): 1, (0, 1): -2, (0, 0): 5}))   # |x - (2,1)|^2
q2 = pad(poly({(2, 0): 1, (1, 0): -2, (0, 2): 1, (0, 1): -4, (0, 0): 5}))   # |x - (1,2)|^2
psi = mul(q1, q2)
w = [pad(poly({(2, 0): 1, (1, 0): -3, (0, 2): 1, (0, 1): -3, (0, 0): 4})),
     pad(poly({(2, 0): 1, (1, 1): 1, (1, 0): -3}))]
u = [dy(psi) + w[0] / lam, -dx(psi) + w[1] / lam]
grad = [[dx(u[0]), dy(u[0])], [dx(u[1]), dy(u[1])]]
div_u = grad[0][0] + grad[1][1]
sigma = [[mu * (grad[i][j] + grad[j][i]) + (lam * div_u if i == j else 0) for j in range(2)]
         for i in range(2)]
div_sigma = [dx(sigma[i][0]) + dy(sigma[i][1]) for i in range(2)]
rotation = 0.5 * (grad[0][1] - grad[1][0])
normal = np.array([1.0, 1.0]) / math.sqrt(2)                # outward normal of roof_right
smooth = nd.Scene(name="pentagon-manufactured",
               geometry=Geometry(kind="polygon", points=POINTS, labels=SIDES, maxh=MAXH),
               boundary={"dirichlet": ["bottom", "right", "roof_left", "left"],
                         "neumann": ["roof_right"]},
               material=Material(E=E, nu=NU),
               loads=Loads(body_force=[text(-d) for d in div_sigma],
                           traction=[text(normal[0] * sigma[i][0] + normal[1] * sigma[i][1])
                                     for i in range(2)],
                           displacement=[text(c) for c in u]))
nd.validate(smooth)


def cf(a: np.ndarray) -> ngs.CoefficientFunction:
    return Expression(text(a)).coefficient()


EXACT = {"sigma": ngs.CF(tuple(cf(sigma[i][j]) for i in range(2) for j in range(2)), dims=(2, 2)),
         "div_sigma": ngs.CF(tuple(cf(d) for d in div_sigma)),
         "u": ngs.CF(tuple(cf(c) for c in u)), "eta": cf(rotation)}


def exact_error(solution) -> float:
    """e = (||sigma - sigma_h||^2 + ||div(sigma - sigma_h)||^2 + ||u - u_h||^2
    + ||eta - eta_h||^2)^(1/2), computed exactly (polynomials, order 8)."""
    f = nd.fields(solution)
    m = solution.problem.fes.mesh
    diffs = (EXACT["sigma"] - f.sigma, EXACT["div_sigma"] - f.div_sigma, EXACT["u"] - f.u,
             EXACT["eta"] - f.eta)
    return math.sqrt(sum(ngs.Integrate(ngs.InnerProduct(d, d), m, order=8) for d in diffs))


print(f"u_1 = {text(u[0])[:90]}...")

# %% [markdown]
# ## 4. Effectivity under uniform refinement
#
# For each level: the exact error $e$, the estimator
# $\eta = (\sum_T \eta_{tot,T}^2)^{1/2}$ and the effectivity index $\eta/e$. Reliability
# (Theorem 4.8) says $\eta/e$ is bounded below; a good estimator is also *efficient*,
# $\eta/e$ bounded above, so that the index stays in a band.

# %%
rows = []
for level in LEVELS:
    solution_s = nd.solve(smooth, level)
    l2, hdiv = nd.estimate(solution_s), nd.estimate(solution_s, asymmetry="hdiv")
    rows.append({"level": level, "ndof": int(sum(solution_s.problem.spaces.dofs().values())),
                 "error": exact_error(solution_s), "eta": l2.total, "eta_hdiv": hdiv.total,
                 "terms": {k: math.sqrt(v) for k, v in l2.summed().items()},
                 "as_l2": math.sqrt(l2.summed()["asymmetry"]),
                 "as_hdiv": math.sqrt(hdiv.summed()["asymmetry"])})
ndofs = [r["ndof"] for r in rows]
for key in ("error", "eta"):  # ngdual.rates: the order in h_N = N^(-1/2)
    for row, rate in zip(rows[1:], observed_rates(ndofs, [r[key] for r in rows])[1:]):
        row[f"rate_{key}"] = rate
effectivity = [row["eta"] / row["error"] for row in rows]
print(f"{'level':>5} {'ndof':>7} {'error':>10} {'eta':>10} {'eta/e':>6} {'rate e':>7} "
      f"{'rate eta':>8}")
for row, eff in zip(rows, effectivity):
    rates = (f"{row['rate_error']:7.2f} {row['rate_eta']:8.2f}" if "rate_error" in row
             else f"{'':>7} {'':>8}")
    print(f"{row['level']:5d} {row['ndof']:7d} {row['error']:10.3e} {row['eta']:10.3e} "
          f"{eff:6.3f} {rates}")
print(f"effectivity band: [{min(effectivity):.3f}, {max(effectivity):.3f}]")

# %% [markdown]
# The error halves with $h$ (first order, Theorem 3.35), and so does $\eta$: the
# effectivity index hardly moves. Which terms make up $\eta$ here? No contact, so the
# contact and friction terms vanish; the rates (`ngdual.rates.observed_rates` between the
# last two levels) show that every term decays at first order:

# %%
active_terms = [k for k in TERMS if rows[-1]["terms"][k] > 1e-12 * rows[-1]["eta"]]
print(f"{'term':15s} " + " ".join(f"{'level ' + str(r['level']):>10}" for r in rows) + "   rate")
for name in active_terms:
    values = [r["terms"][name] for r in rows]
    print(f"{name:15s} " + " ".join(f"{v:10.3e}" for v in values)
          + f"   {observed_rates(ndofs[-2:], values[-2:])[1]:4.2f}")

fig, ax = plt.subplots(figsize=(6.5, 4.5))
ax.loglog(ndofs, [r["error"] for r in rows], "o-", label="error e")
ax.loglog(ndofs, [r["eta"] for r in rows], "s-", label=r"$\eta$, as($\sigma_h$) in $L^2$")
ax.loglog(ndofs, [r["eta_hdiv"] for r in rows], "^--",
          label=r"$\eta$, as($\sigma_h$) in $H(\mathrm{div})$ (4.15)")
ax.loglog(ndofs, [rows[0]["error"] * (n / ndofs[0]) ** -0.5 for n in ndofs], "k:",
          label=r"$N^{-1/2}$ (first order in h)")
ax.set_xlabel("degrees of freedom N")
ax.set_ylabel("error / estimator")
ax.set_title("Smooth problem on the pentagon, uniform refinement")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
save_figure(fig, OUT / "effectivity.png")

# %% [markdown]
# ## 5. Why $\operatorname{as}(\sigma_h)$ is measured in $L^2$
#
# (4.15) as printed uses
# $\|\operatorname{as}(\sigma_h)\|^2_{H(\operatorname{div},T)} =
# \|\operatorname{as}(\sigma_h)\|^2_T + \|\operatorname{div}\operatorname{as}(\sigma_h)\|^2_T$.
# For the skew part
# $\operatorname{as}(\sigma_h) = \begin{pmatrix} 0 & a \\ -a & 0 \end{pmatrix}$,
# $a = (\sigma_{12} - \sigma_{21})/2$, $\operatorname{div}\operatorname{as}(\sigma_h) = \nabla a$
# up to a rotation. Now look at the $RT_0$ part of a PEERS row on $T$:
# $r_i = p_i + c_i(x - x_T)$, with $\operatorname{div} r_i = 2c_i = -\bar f_i$ (the mean of
# $f$ on $T$, by the second row of (3.62)). Then $\sigma_{12} - \sigma_{21}$ contains
# $c_1(y - y_T) - c_2(x - x_T)$, whose gradient $(-c_2, c_1)$ has length $|\bar f|/2$:
# $|\nabla a| \approx |\bar f_T|/4$ on *every* element, whatever $h$. The Curl bubbles do
# not remove it. So $\|\operatorname{div}\operatorname{as}(\sigma_h)\|$ stays of the size
# $\|f\|/4$ although $\operatorname{as}(\sigma) = 0$, and $\eta$ with the
# $H(\operatorname{div})$ norm stalls while the error keeps decreasing: its effectivity
# index grows like $1/h$. With the $L^2$ norm (Carstensen-Dolzmann, Gatica et al.) the
# asymmetry decreases at first order like every other term. This is `asymmetry="l2"`,
# the default.

# %%
mesh1 = nd.solve(smooth, LEVELS[0]).problem.fes.mesh
body = ngs.CF(tuple(cf(-d) for d in div_sigma))
quarter_f = 0.25 * math.sqrt(ngs.Integrate(body * body, mesh1, order=8))
hdiv_ratio = [r["eta_hdiv"] / r["error"] for r in rows]
print(f"||f||/4 = {quarter_f:.3e}")
print(f"{'level':>5} {'|as|_L2':>10} {'|as|_Hdiv':>10} {'/ (||f||/4)':>11} {'eta_Hdiv/e':>10}")
for row, ratio in zip(rows, hdiv_ratio):
    print(f"{row['level']:5d} {row['as_l2']:10.3e} {row['as_hdiv']:10.3e} "
          f"{row['as_hdiv'] / quarter_f:11.2f} {ratio:10.2f}")

# %% [markdown]
# $\|\operatorname{as}(\sigma_h)\|_{H(\operatorname{div})}$ stays at about $\|f\|/4$ on
# every level (the bubbles add a little), while $\|\operatorname{as}(\sigma_h)\|_{L^2}$
# halves with $h$. The $H(\operatorname{div})$ effectivity index roughly doubles per
# level. This is the growth of $\eta_{as}^{\max}$ that the thesis observed in Table 4.2
# and blamed for the poor effectivity indices of Table 4.4.

# %%
results = {
    "quick": QUICK, "levels": LEVELS,
    "thesis": {"level": THESIS_LEVEL, "eta": est.total, "summed": summed,
               "elements": mesh.ne,
               "sum_of_terms_is_eta2": bool(np.allclose(est.eta**2, sum(est.terms.values()))),
               "friction_elements": int(np.count_nonzero(est.terms["friction"])),
               "neumann_elements": int(np.count_nonzero(est.terms["neumann"]))},
    "smooth": rows, "effectivity": effectivity, "hdiv_effectivity": hdiv_ratio,
    "quarter_f": quarter_f,
}
print(f"wrote {save_results('06_estimator', results)}")

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/06_estimator_solutions.py`.
#
# 1. **Patch test.** For an affine displacement $u = Gx + c$ ($G$ not symmetric) PEERS
#    reproduces $\sigma$ and $\eta$ exactly. Build such a scene on the pentagon
#    ($u_D = u$ on $\Gamma_D$, the traction $\sigma n$ on the Neumann side, $f = 0$) and
#    check that every term of $\eta_{\sigma,T}$ and the Neumann term vanish, while
#    $\eta_{u,T}$ does not. Why can $\eta_{u,T}$ not vanish?
# 2. **Table 4.2.** On Example 3.46 with Coulomb friction, levels 1-4 (uniform), compute
#    $\eta_{as}^{\max} = \max_T \eta_{as,T}$ and $q_{as}$, the share of triangles with
#    $\eta_{as,T} \ge 0.1\,\eta_{as}^{\max}$, with $\operatorname{as}(\sigma_h)$ in $L^2$
#    and in $H(\operatorname{div})$. Where is the maximum attained?
# 3. **Sum or square root of the sum of squares?** Theorem 4.8 bounds the error by
#    $\sum_T \eta_{tot,T}$ (`Estimate.total_sum`, the $\eta_{tot}$ of Table 4.4), not by
#    $(\sum_T \eta_{tot,T}^2)^{1/2}$ (`Estimate.total`). Compute the ratio of the two
#    under uniform refinement for the smooth clamped square of Tutorial 2 and for
#    Example 3.46 without friction, and compare it with $\sqrt{\text{number of triangles}}$.
#    What does this mean for an effectivity index computed with $\sum_T \eta_{tot,T}$?
