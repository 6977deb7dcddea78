# %% [markdown]
# # Tutorial 6: The a posteriori error estimator of Chapter 4
#
# **Run time** on a 2-core laptop: about 5 s; about 6 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 06 --quick`).
#
# **The idea in words.** The error of a finite element solution is not known without the
# exact solution, but it can be estimated from the computed solution alone: on every
# triangle, measure how far the discrete stress is from satisfying what the exact one
# satisfies (equilibrium, symmetry, compatibility, the boundary conditions and the contact
# and friction laws). The sum of these local indicators bounds the error from above and
# below up to constants, and the local values show where the mesh should be refined. The
# pictures show where each term lives and how the estimate tracks the true error.
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
# (with (4.49)): $\eta_{\sigma,T}$ of (4.15) and $\eta_{u,T}$ of (4.31) (residuals of the
# stress and displacement equations), a friction term on $A_C$, a Neumann term on $\Gamma_N$.
#
# **Discretisation.** PEERS (3.61) on the fine mesh, $P_1$ multipliers on the coarse
# boundary meshes. The indicators are element and edge integrals of the discrete fields;
# $w_h = \mathbb{C}^{-1}\sigma_h + \eta_h$ (the rotation as a skew tensor) approximates
# $\nabla u$.
#
# **What you will learn.** What the estimator (4.50) measures and whether it can be trusted:
# `nd.estimate` returns one array per term and element; each term lives where its residual
# is made (corners, $\Gamma_N$, $\Gamma_C$), and on a smooth problem $\eta/e$ stays in a
# narrow band, provided the asymmetry is measured in $L^2$, not in $H(\operatorname{div})$
# as printed in (4.15) (cf. Table 4.2).
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
import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np
from matplotlib.colors import LogNorm

import ngdual as nd

lesson = nd.Lesson("06_estimator")               # figures and results.json go here
QUICK = lesson.quick
THESIS_LEVEL = 3 if QUICK else 4              # Example 3.46 for the pictures of every term
LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4, 5]   # uniform levels of the smooth problem
E, NU, MAXH = 100.0, 0.3, 0.4                 # material and mesh size of the smooth problem

# %% [markdown]
# ## 1. The terms of (4.50)
#
# With $t$ the unit tangent, $[\cdot]$ the jump across an interior edge, $u_\Gamma$ the
# value of the piecewise constant $u_h$ at a boundary edge and $\tilde h_e$ the coarse
# edge holding $e$:
#
# * `residual`: $\|f + \operatorname{div}\sigma_h\|_T^2$, the equilibrium
#   $\operatorname{div}\sigma = -f$;
# * `asymmetry`: $\|\operatorname{as}(\sigma_h)\|_T^2$, the symmetry of $\sigma$ (in
#   $L^2$, Section 4);
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
# The first seven make $\eta_{\sigma,T}$ (4.15), the next four $\eta_{u,T}$ (4.31). An
# `Estimate` holds the *squared* contribution per element; $\eta_{tot,T}^2$ is their sum.

# %% [markdown]
# ## 2. Every term on Example 3.46 with Coulomb friction
#
# One solve, one call of `nd.estimate`. (The solve warns: the thesis' scene forces
# $u_n = g$ at the clamped corners, `ends = "thesis"`, kept to reproduce its tables; the
# estimator sees the same defect below.) The squared terms summed over the mesh show which
# dominate $\eta$, the pictures where they live (one logarithmic colour scale per term;
# white elements have a zero or round-off indicator).

# %%
thesis = nd.load_scene("thesis-3.46-coulomb")
lesson.save(nd.plot_geometry(thesis, level=THESIS_LEVEL), "geometry")
solution = nd.solve(thesis, THESIS_LEVEL)
est = nd.estimate(solution)
mesh = solution.problem.fes.mesh
summed = est.summed()
print(f"level {THESIS_LEVEL}: {mesh.ne} triangles, eta = {est.total:.4e}")
for name, value in sorted(summed.items(), key=lambda item: -item[1]):
    print(f"  {name:15s} {np.sqrt(value):10.3e}   ({100 * value / est.total**2:5.1f} % of eta^2)")


def plot_terms(mesh, terms: dict, title: str, columns: int = 2):
    """One tripcolor panel per (squared) indicator term, log colour scale, zeros blank."""
    tri = mtri.Triangulation(*nd.mesh_arrays(mesh)[0].T, nd.mesh_arrays(mesh)[1])
    rows = int(np.ceil(len(terms) / columns))
    largest = max(float(np.max(values)) for values in terms.values())
    fig, axes = plt.subplots(rows, columns, squeeze=False, figsize=(
        6.5 * columns, 6.5 * rows * np.ptp(tri.y) / np.ptp(tri.x) + 1.2))
    for ax, (name, values) in zip(axes.flat, terms.items()):
        ax.set(aspect="equal", xticks=[], yticks=[])
        ax.triplot(tri, color="0.85", lw=0.2)
        top = float(np.max(values))
        if top <= 1e-12 * largest:
            ax.set_title(f"{name}: zero up to round-off", fontsize=9)
            continue
        art = ax.tripcolor(tri, facecolors=np.ma.masked_less_equal(values, 1e-8 * top),
                           norm=LogNorm(1e-8 * top, top), cmap="viridis", edgecolors="none")
        fig.colorbar(art, ax=ax, fraction=0.03, pad=0.01)
        ax.set_title(f"{name}: sum {np.sum(values):.2e}", fontsize=9)
    for ax in list(axes.flat)[len(terms):]:
        ax.axis("off")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


lesson.save(plot_terms(mesh, {"eta_tot^2": est.indicators**2, **est.terms}, "Squared indicators of "
                       f"(4.50), Example 3.46, mu_f = 0.5, level {THESIS_LEVEL}"),
            "terms_thesis_coulomb")

# %% [markdown]
# `residual` vanishes: $f = 0$, and $\operatorname{div}\sigma_h = -\Pi_0 f$ holds exactly
# in PEERS. The terms in $\sigma$ (`asymmetry`, `friction`, `neumann`) are stresses, of the
# size of $t_0 \approx 800$; the terms in $w_h \approx \nabla u$ are strains, some
# $E \approx 2\cdot 10^5$ times smaller: the stress terms decide where $\eta$ is large
# (Figs. 4.1-4.8). `asymmetry`, `curl` and the jumps peak in the corners, largest in the
# two lower ones, where $\lambda_n \in C_{\tilde h}$ must vanish ($u_n = g = 0.01$) while
# $u = 0$ on $\Gamma_D$: the data jump, $\sigma \sim 1/r$, and these indicators do not
# decrease under refinement (Table 4.2, Tutorial 7). `neumann` and `jump_neumann` live at
# $\Gamma_N$, largest where $t_0$ switches off ($x_1 = \pm 2$); `friction` along
# $\Gamma_C$, where the pointwise $\sigma_t$ differs from $\mathcal{F}\nu$ ($(3.62)_5$
# holds only tested with the hats); `jump_contact` at the ends of $\Gamma_C$.
#
# ## 3. A smooth problem with a known solution
#
# To measure the effectivity index $\eta/e$ we need the exact error $e$. The convex
# pentagon with corners $(0,0)$, $(2,0)$, $(2,1)$, $(1,2)$, $(0,1)$, Neumann side from
# $(2,1)$ to $(1,2)$, Dirichlet elsewhere, and the polynomial displacement
#
# $$
# u = \operatorname{Curl}\psi + w/\lambda, \qquad
# \psi = |x - p_1|^2\,|x - p_2|^2, \qquad
# w = (x^2 - 3x + y^2 - 3y + 4,\ x^2 + xy - 3x),
# $$
#
# $p_1 = (2,1)$, $p_2 = (1,2)$: $u$, $\sigma$, $f$ and $t_0$ are polynomials, computed
# exactly by `Piecewise` (here without breakpoints) and written as scene formulas.

# %%
x, y = nd.verification.Piecewise.x(), nd.verification.Piecewise.y()
lam, mu = nd.scene.Material(E, NU).lame
psi = ((x - 2) ** 2 + (y - 1) ** 2) * ((x - 1) ** 2 + (y - 2) ** 2)
w = [x * x - x * 3 + y * y - y * 3 + 4, x * x + x * y - x * 3]
u = [psi.dy() + w[0] / lam, -psi.dx() + w[1] / lam]
grad = [[c.dx(), c.dy()] for c in u]
div_u = grad[0][0] + grad[1][1]
sigma = [[(grad[i][j] + grad[j][i]) * mu + (div_u * lam if i == j else 0) for j in range(2)]
         for i in range(2)]
div_sigma = [sigma[i][0].dx() + sigma[i][1].dy() for i in range(2)]
roof = [sigma[i][0] / np.sqrt(2) + sigma[i][1] / np.sqrt(2) for i in range(2)]  # n = (1, 1)/√2
smooth = nd.Scene(name="pentagon-manufactured",
                  geometry=nd.scene.Geometry(kind="polygon", maxh=MAXH,
                                    points=[(0, 0), (2, 0), (2, 1), (1, 2), (0, 1)],
                                    labels=["bottom", "right", "roof_right", "roof_left", "left"]),
                  boundary={"dirichlet": ["bottom", "right", "roof_left", "left"],
                            "neumann": ["roof_right"]},
                  material=nd.scene.Material(E=E, nu=NU),
                  loads=nd.scene.Loads(body_force=[(-d).text() for d in div_sigma],
                              traction=[t.text() for t in roof],
                              displacement=[c.text() for c in u]))
lesson.save(nd.plot_geometry(smooth, level=LEVELS[-1]), "geometry_smooth")


# σ, div σ, u and η as NGSolve fields: nd.coefficient of their formulas
EXACT = (nd.coefficient([[c.text() for c in row] for row in sigma]),
         nd.coefficient([c.text() for c in div_sigma]), nd.coefficient([c.text() for c in u]),
         nd.coefficient(((grad[0][1] - grad[1][0]) / 2).text()))


def exact_error(solution) -> float:
    """e^2 = ||σ - σ_h||^2 + ||div(σ - σ_h)||^2 + ||u - u_h||^2 + ||η - η_h||^2, exactly."""
    f = nd.fields(solution)
    mesh = solution.problem.fes.mesh
    return float(np.sqrt(sum(nd.l2_norm(exact - h, mesh, order=8) ** 2 for exact, h in
                             zip(EXACT, (f.sigma, f.div_sigma, f.u, f.eta)))))


# %% [markdown]
# ## 4. Effectivity under uniform refinement
#
# Per level: the exact error $e$, $\eta = (\sum_T \eta_{tot,T}^2)^{1/2}$ and the effectivity
# index $\eta/e$, bounded below by reliability (Theorem 4.8) and above by efficiency, so that
# it stays in a band; for comparison also with the asymmetry in $H(\operatorname{div})$.

# %%
rows = []
for level in LEVELS:
    solution_s = nd.solve(smooth, level)
    l2, hdiv = nd.estimate(solution_s), nd.estimate(solution_s, asymmetry="hdiv")
    rows.append({"level": level, "ndof": int(sum(solution_s.problem.spaces.dofs().values())),
                 "error": exact_error(solution_s), "eta": l2.total, "eta_hdiv": hdiv.total,
                 "terms": {k: float(np.sqrt(v)) for k, v in l2.summed().items()},
                 "as_l2": float(np.sqrt(l2.summed()["asymmetry"])),
                 "as_hdiv": float(np.sqrt(hdiv.summed()["asymmetry"]))})
ndofs = [r["ndof"] for r in rows]
for key in ("error", "eta"):  # nd.rates: the order in h_N = N^(-1/2)
    for row, rate in zip(rows[1:], nd.rates.observed_rates(ndofs, [r[key] for r in rows])[1:]):
        row[f"rate_{key}"] = rate
effectivity = [row["eta"] / row["error"] for row in rows]
hdiv_ratio = [r["eta_hdiv"] / r["error"] for r in rows]
print(f"{'level':>5} {'ndof':>7} {'error':>10} {'eta':>10} {'eta/e':>6} {'rate e':>7} "
      f"{'rate eta':>8} {'eta_Hdiv/e':>10}")
for row, eff, ratio in zip(rows, effectivity, hdiv_ratio):
    rates = (f"{row['rate_error']:7.2f} {row['rate_eta']:8.2f}" if "rate_error" in row
             else f"{'':>7} {'':>8}")
    print(f"{row['level']:5d} {row['ndof']:7d} {row['error']:10.3e} {row['eta']:10.3e} "
          f"{eff:6.3f} {rates} {ratio:10.2f}")

fig, ax = plt.subplots(figsize=(6.5, 4.5))
ax.loglog(ndofs, [r["error"] for r in rows], "o-", label="error e")
ax.loglog(ndofs, [r["eta"] for r in rows], "s-", label=r"$\eta$, as($\sigma_h$) in $L^2$")
ax.loglog(ndofs, [r["eta_hdiv"] for r in rows], "^--",
          label=r"$\eta$, as($\sigma_h$) in $H(\mathrm{div})$ (4.15)")
ax.loglog(ndofs, [rows[0]["error"] * (n / ndofs[0]) ** -0.5 for n in ndofs], "k:",
          label=r"$N^{-1/2}$ (first order in h)")
ax.set(xlabel="degrees of freedom N", ylabel="error / estimator",
       title="Smooth problem on the pentagon, uniform refinement")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
lesson.save(fig, "effectivity")

# %% [markdown]
# The error halves with $h$ (first order, Theorem 3.35), and so does $\eta$: the
# effectivity index hardly moves. With the asymmetry in $H(\operatorname{div})$ it grows
# like $1/h$: on every element the $RT_0$ part of a PEERS row, $r_i = p_i + c_i(x - x_T)$
# with $2c_i = -\bar f_i$, puts $c_1(y - y_T) - c_2(x - x_T)$ into
# $\sigma_{12} - \sigma_{21}$, so $|\operatorname{div}\operatorname{as}(\sigma_h)| \approx
# |\bar f_T|/4$ whatever $h$, although $\operatorname{as}(\sigma) = 0$. That term stalls
# while the error decreases: the growth of $\eta_{as}^{\max}$ in Table 4.2, blamed there
# for the effectivity indices of Table 4.4. In $L^2$ (Carstensen-Dolzmann, Gatica et al.,
# ngdual's default `asymmetry="l2"`) it decays at first order like every other term.

# %%
lesson.results({
    "levels": LEVELS,
    "thesis": {"level": THESIS_LEVEL, "eta": est.total, "summed": summed,
               "elements": mesh.ne,
               "sum_of_terms_is_eta2": bool(np.allclose(est.indicators**2,
                                                        sum(est.terms.values()))),
               "friction_elements": int(np.count_nonzero(est.terms["friction"])),
               "neumann_elements": int(np.count_nonzero(est.terms["neumann"]))},
    "smooth": rows, "effectivity": effectivity, "hdiv_effectivity": hdiv_ratio,
})

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
