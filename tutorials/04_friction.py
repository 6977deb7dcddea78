# %% [markdown]
# # Tutorial 4: Tresca and Coulomb friction, the nested Uzawa algorithm
#
# **Problem.** Example 3.46 of the thesis *with* friction: the block $[-4,4]\times[-1,1]$,
# clamped at its ends, pressed by a parabolic traction on top onto a rigid foundation
# at distance $g$ below $\Gamma_C$. On the contact part the body may stick or slip. With a
# friction bound $\mathcal{F} \ge 0$ (Tresca: given; Coulomb:
# $\mathcal{F} = \mu_f|\sigma_n|$) the conditions read
#
# $$
# |\sigma_t| \le \mathcal{F}, \qquad
# |\sigma_t| < \mathcal{F} \Rightarrow u_t = 0 \ \text{(stick)}, \qquad
# |\sigma_t| = \mathcal{F} \Rightarrow u_t = -\kappa\,\sigma_t,\ \kappa \ge 0 \ \text{(slip)}.
# $$
#
# The dual-dual formulation (3.41) removes the non-differentiable friction work
# $j(\lambda_t) = \int_{\Gamma_C} \mathcal{F}|\lambda_t|\,ds$ with one more multiplier
# $\nu \in \Lambda = \{|\nu| \le 1\}$ on $A_C = \operatorname{supp}\mathcal{F}$, "the sign
# of $\lambda_t$" (Remark 3.15): $\nu\lambda_t = |\lambda_t|$, $\sigma_t = \mathcal{F}\nu$.
#
# **Discretisation.** PEERS for $(\sigma, u, \eta)$, $P_1$ multipliers $\varphi$ on
# $\Gamma_N$ and $\lambda_t$, $\lambda_n$ on the coarse mesh $\tilde h = 2h$ of
# $\Gamma_C$, and $\nu$ piecewise constant on a mesh $\hat h = 2\tilde h$ of $\Gamma_C$
# with $|\nu| \le 1$: the discrete variational inequality (3.62) with
# $q(\kappa, \mu) = \int_{\Gamma_C} \mathcal{F}\kappa\mu\,ds$. (Why $\hat h = 2\tilde h$
# and not $\hat h = \tilde h$ is the subject of Tutorial 5.)
#
# **What you will learn.**
# 1. Algorithm 3.41: an inner Uzawa loop for $\lambda_n$ (the Signorini problem of
#    Tutorial 3 with a prescribed tangential load) inside an outer loop for $\nu$, and the
#    exchanged loop order of Remark 3.43; the box projection $P^\Lambda$ of Remark 3.44.
# 2. Coulomb friction as a fixed point on $\mathcal{F} = \mu_f|\sigma_n|$ (Remark 3.45,
#    (3.123)), computed inside the same outer loop, and a check against an independent
#    QP solver.
# 3. How to read stick, slip and separation on $\Gamma_C$, and why $\nu$ is the sign of
#    $\lambda_t$.
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011: Sections 3.1.4, 3.2.2 and
# 3.3.3: eqs. (3.41), (3.42), (3.62), (3.95), (3.123), Algorithm 3.41, Theorem 3.42,
# Remarks 3.43-3.45, Example 3.46, Figs. 3.19-3.23. M. Maischak, *FEM/BEM methods for
# Signorini-type problems* (Habilitation, Hannover 2004), Section 5.3. R. Glowinski,
# *Numerical methods for nonlinear variational problems* (1984), Chapter II.5.

# %% [markdown]
# ## Parameters
# The nested Uzawa algorithm is the subject, so besides the public API
# (`import ngdual as nd`) its building blocks are imported from their modules.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd
from ngdual import peers, post
from ngdual.forms import assemble
from ngdual.friction import build_friction_forms
from ngdual.mesh import build_mesh
from ngdual.solvers import solve_problem
from ngdual.solvers.nested import box_projection, box_projection_qp, nested_uzawa
from ngdual.solvers.reference import solve_qp_friction
from ngdual.solvers.settings import Model, NestedUzawaSettings
from ngdual.studies.tutorials import (
    draw,
    output_dir,
    plot_geometry,
    plot_von_mises,
    quick_mode,
    save_figure,
    save_results,
)

QUICK = quick_mode()
LEVEL = 3 if QUICK else 4                        # mesh level of Example 3.46
LOOP_ORDERS = ["friction-outer", "contact-outer"]  # Algorithm 3.41 and Remark 3.43
EPS1, EPS2 = 1e-10, 1e-9                         # tight tolerances, to compare with the QP
OUT = output_dir("04_friction")
print(f"quick mode: {QUICK}; level {LEVEL}; output in {OUT}")

# %% [markdown]
# ## 1. The friction multiplier $\nu$ and the matrix $Q_{\mathcal{F}}$
#
# Compared with Tutorial 3, (3.62) has two more lines:
#
# $$
# \begin{aligned}
# d_{C,t}(\mu_t, \sigma) - q(\mu_t, \nu) &= 0 && \forall \mu_t \in C_{\tilde h}
#   && (\sigma_t = \mathcal{F}\nu \text{, tested}),\\
# q(\kappa - \nu, \lambda_t) &\le 0 && \forall \kappa \in \Lambda_{\hat h}
#   && (\nu\lambda_t = |\lambda_t|).
# \end{aligned}
# $$
#
# In matrices (3.95)-(3.97): the $\lambda_t$ rows of the saddle-point system get the load
# $Q_{\mathcal{F}}^\top\nu$, where $(Q_{\mathcal{F}})_{ji} = q(\mu_i, \kappa_j)$ couples the
# $\tilde h$ hat $\mu_i$ with the indicator $\kappa_j$ of the $\hat h$ edge $j$.
# `build_friction_forms` provides everything on $\Gamma_C$: $\sigma_n$ and $\sigma_t$ on
# the fine edges as matrices (`T_n @ x`), the $\hat h$ edge of every fine edge, and
# `q_matrix(F)`. The Tresca scene has the constant bound $\mathcal{F} = 100$ ($\sigma_n$
# reaches about $-500$ under the load).

# %%
tresca = nd.load_scene("thesis-3.46-tresca")
coulomb = nd.load_scene("thesis-3.46-coulomb")
save_figure(plot_geometry(coulomb, level=LEVEL,
                          title=f"Example 3.46 with friction: boundary parts, level {LEVEL}"),
            OUT / "geometry.png")
mu_f = coulomb.friction.mu
problem_t = assemble(tresca, build_mesh(tresca.geometry, LEVEL))
problem_c = assemble(coulomb, build_mesh(coulomb.geometry, LEVEL))
forms = build_friction_forms(problem_t)
print(f"dofs (Table 3.1, L = nu on the h^ mesh): {problem_t.spaces.dofs()}")
print(f"fine edges on Gamma_C: {len(forms.lengths)}, h^ edges (nu): {forms.n_nu}, "
      f"Q_F: {forms.q_matrix(np.ones(len(forms.lengths))).shape} (N_A x N_C)")

# %% [markdown]
# ## 2. Algorithm 3.41 for Tresca friction
#
# The nested Uzawa algorithm alternates two projections:
#
# * **inner loop** (steps 4-7): for fixed $\nu$, Algorithm 3.38 on $\lambda_n$: solve the
#   saddle point system with the loads $-C_n\lambda_n$ and $Q_{\mathcal{F}}^\top\nu$, then
#   $\lambda_n \leftarrow P^+(\lambda_n + \rho_1\Phi(\sigma))$;
# * **outer step** (step 8): $\nu \leftarrow P^\Lambda(\nu + \rho_2\,\Phi^\Lambda\lambda_t)$,
#   a projected gradient step for $\nu$.
#
# Remark 3.44 poses $P^\Lambda$ like $P^+$ (Remark 3.40) as a QP in the mass matrix $M$ of
# $L_{\hat h}$:
# $\nu = \operatorname{argmin}_{|\psi_j| \le 1} \tfrac12\psi^\top M\psi - \psi^\top b$.
# $\nu$ is piecewise constant, so $M$ is *diagonal* and the QP decouples into
# $\operatorname{clip}(b/M, -1, 1)$; unlike $P^+$ in the dense $H^{1/2}$ metric $W$, here
# clipping is exact. ngdual uses the closed form (by default with $M$ scaled by the
# diagonal of the $\nu$ operator, `friction_metric="jacobi"`, still diagonal); the cvxpy
# QP agrees.

# %%
rng = np.random.default_rng(3)
masses, loads = rng.uniform(0.5, 2.0, forms.n_nu), rng.normal(scale=2.0, size=forms.n_nu)
box_qp_difference = float(np.max(np.abs(box_projection_qp(loads, masses)
                                        - box_projection(loads, masses))))
print(f"P^Lambda: |cvxpy QP - clip(b / M, -1, 1)| = {box_qp_difference:.1e}")

# %% [markdown]
# `nested_uzawa` runs Algorithm 3.41 (`loop_order="friction-outer"`) or, with the loops
# exchanged (Remark 3.43), an inner loop for $\nu$ at fixed $\lambda_n$ inside an outer
# loop for $\lambda_n$ (`"contact-outer"`). $\rho_2$ is dimensionless (relative to the
# computed stability bound of the $\nu$ step, see `FrictionStep`), so $0 < \rho_2 < 2$
# converges for any $E$ and load. It stops only when the increments *and* the residual of
# $\nu\lambda_t = |\lambda_t|$ are below $\varepsilon_2$.

# %%
tresca_runs = {order: nested_uzawa(problem_t, NestedUzawaSettings.from_scene(
                   tresca, eps1=EPS1, eps2=EPS2, loop_order=order))
               for order in LOOP_ORDERS}
for order, solution in tresca_runs.items():
    print(f"Tresca, {order:14s}: {solution.iterations['outer']:4d} outer, "
          f"{solution.iterations['inner']:5d} inner iterations, converged {solution.converged}")

# %% [markdown]
# With $\nu$ outside (Algorithm 3.41) each outer step solves a whole contact problem, so
# there are few outer and many inner steps; exchanged, the cheap $\nu$ iteration runs
# inside. Both reach the same discrete solution: (3.62) has a unique $\sigma$, and with
# $\hat h = 2\tilde h$ a unique $\nu$.

# %%
def relative(a, b) -> float:
    return float(np.linalg.norm(a - b) / (np.linalg.norm(b) or 1.0))


first, second = (tresca_runs[o] for o in LOOP_ORDERS)
loop_order_difference = {"tresca": relative(second.x, first.x)}
print(f"Tresca: the two loop orders differ by {loop_order_difference['tresca']:.1e} (relative)")

# %% [markdown]
# ## 3. An independent check: one QP in $(\sigma, \nu)$
#
# For a *given* $\mathcal{F}$, (3.62) is the KKT system of
#
# $$
# \min_{\sigma, \nu}\ \tfrac12\,\sigma^\top A\sigma - g^\top\sigma
# \quad\text{subject to}\quad
# B^\top\sigma - (0, 0, 0, Q_{\mathcal{F}}^\top\nu) = b, \quad
# C_n^\top\sigma \le 0, \quad |\nu_j| \le 1,
# $$
#
# whose multipliers are $(u, \eta, \varphi, \lambda_t)$ and $\lambda_n \ge 0$;
# stationarity in $\nu$ is exactly $\nu_j = \operatorname{sign}(Q_{\mathcal{F}}\lambda_t)_j$,
# i.e. $(3.62)_7$. `solve_qp_friction` hands this QP to Clarabel. It shares only the
# matrices with the nested Uzawa loops.


# %%
def compare(nested, qp) -> dict:
    """Relative differences of sigma, lambda_t, lambda_n and nu (where F matters)."""
    pb = nested.problem
    fr = build_friction_forms(pb)
    lam_scale = max(np.linalg.norm(qp.part("lam_n")), np.linalg.norm(qp.part("lam_t")))
    F_hat = fr.per_hat_edge(qp.friction_bound)
    relevant = F_hat > 1e-3 * F_hat.max()
    return {"sigma": relative(nested.part(*peers.STRESS), qp.part(*peers.STRESS)),
            "lam_t": relative(nested.part("lam_t"), qp.part("lam_t")),
            "lam_n": float(np.linalg.norm(nested.part("lam_n") - qp.part("lam_n")) / lam_scale),
            "nu": float(np.max(np.abs(nested.nu - qp.nu)[relevant]))}


qp_tresca = solve_qp_friction(problem_t, Model.of(tresca))
agreement = {"tresca": compare(tresca_runs["friction-outer"], qp_tresca)}
print("nested Uzawa vs QP, Tresca:", {k: f"{v:.1e}" for k, v in agreement["tresca"].items()})

# %% [markdown]
# ## 4. Coulomb friction: a fixed point on $\mathcal{F}$
#
# Coulomb's law makes the bound depend on the solution, $\mathcal{F} = \mu_f|\sigma_n|$:
# a quasi-variational inequality. Solving Tresca problems for
# $\mathcal{F}^{k+1} = \mu_f|\sigma_n^k|$ in turn would add a third loop. Remark 3.45
# instead updates $\mathcal{F}$ *inside* the outer loop of Algorithm 3.41, before each
# $\nu$ step (steps 8'-10'), starting from the frictionless solution. $\mathcal{F}$ must
# live in $L_{\hat h}$, so (3.123) averages $|\sigma_n|$ over every $\hat h$ edge:
# `forms.coulomb_bound_of(sigma_n, mu_f)`. (ngdual uses by default the $\sigma_n$ that the
# contact conditions actually see, its projection onto the $\tilde h$ hats, so that
# $\mathcal{F}$ vanishes where the body separates; see
# `ngdual.scene.Friction.normal_stress`.)

# %%
coulomb_runs = {order: nested_uzawa(problem_c, NestedUzawaSettings.from_scene(
                    coulomb, eps1=EPS1, eps2=EPS2, loop_order=order))
                for order in LOOP_ORDERS}
for order, solution in coulomb_runs.items():
    print(f"Coulomb mu_f = {mu_f}, {order:14s}: {solution.iterations['outer']:4d} outer, "
          f"{solution.iterations['inner']:5d} inner iterations, converged {solution.converged}")
first, second = (coulomb_runs[o] for o in LOOP_ORDERS)
loop_order_difference["coulomb"] = relative(second.x, first.x)
coulomb_solution = coulomb_runs["friction-outer"]

# %% [markdown]
# At convergence $\mathcal{F}$ is a fixed point: recomputing it from the final $\sigma_n$
# returns the $\mathcal{F}$ the final solution was computed with.

# %%
forms_c = build_friction_forms(problem_c)
sigma_n_edges = forms_c.T_n @ coulomb_solution.x
F_again = forms_c.coulomb_bound_of(sigma_n_edges, mu_f)
fixed_point_residual = float(np.max(np.abs(F_again - coulomb_solution.friction_bound))
                             / np.max(coulomb_solution.friction_bound))
print(f"max |F(sigma_n) - F| / max F = {fixed_point_residual:.1e}")

# %% [markdown]
# The reference solver iterates the QP of Section 3 on $\mathcal{F}$ by successive
# substitution, a genuinely *third* loop. Its history shows how fast the fixed point
# contracts.

# %%
qp_coulomb = solve_qp_friction(problem_c, Model.of(coulomb))
agreement["coulomb"] = compare(coulomb_solution, qp_coulomb)
print(f"QP fixed point: {len(qp_coulomb.history)} QPs, changes of F: "
      f"{np.array2string(np.array(qp_coulomb.history), precision=1)}")
print("nested Uzawa vs QP, Coulomb:", {k: f"{v:.1e}" for k, v in agreement["coulomb"].items()})

# %% [markdown]
# A third route to the same discrete solution: ngdual's default solver (`solve_problem`
# with `solver.method = "auto"`) condenses (3.62) onto $\Gamma_C$ and solves the small
# contact problem there by a semismooth Newton method, with the same fixed point on
# $\mathcal{F}$. It is
# the faster choice in practice; the nested Uzawa algorithm is what the thesis analyses
# (Theorem 3.42), and what this tutorial is about.

# %%
active_set = solve_problem(problem_c)
active_set_difference = compare(coulomb_solution, active_set)
print(f"nested Uzawa vs {active_set.method}:",
      {k: f"{v:.1e}" for k, v in active_set_difference.items()})

fig, ax = plt.subplots(figsize=(7, 4))
for (law, runs) in (("Tresca", tresca_runs), ("Coulomb", coulomb_runs)):
    for order, style in zip(LOOP_ORDERS, ("-", "--")):
        history = np.array(runs[order].history)
        steps = np.arange(1, len(history) + 1)
        # an exact 0: nu saturated at +-1 on every edge, the projection fixes it for good
        ax.semilogy(steps[history > 0], history[history > 0], style, label=f"{law}, {order}")
ax.semilogy(range(1, len(qp_coulomb.history) + 1), qp_coulomb.history, "k:o", ms=3,
            label="Coulomb, QP on F (3rd loop)")
ax.set_xlabel("outer iteration")
ax.set_ylabel("outer residual / change of F")
ax.set_title(f"Nested Uzawa on Example 3.46, level {LEVEL}")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
save_figure(fig, OUT / "outer_histories.png")

# %% [markdown]
# ## 5. Stick, slip and separation on $\Gamma_C$
#
# What the discrete solution satisfies, tested with the $\tilde h$ hats $\mu_i$
# (Proposition 3.25):
#
# * $\lambda_n \ge 0$ (no penetration), $\int\sigma_n\mu_i \le 0$ (compression only),
#   $\lambda_n \cdot \int\sigma_n\mu_i = 0$;
# * $|\int\sigma_t\mu_i| \le \int\mathcal{F}\mu_i$ (the friction cone, tested), and
#   $\int\sigma_t\mu_i = q(\mu_i, \nu)$ exactly;
# * $|\nu| \le 1$ and $\nu = \operatorname{sign}(Q_{\mathcal{F}}\lambda_t)$ wherever
#   $Q_{\mathcal{F}}\lambda_t \ne 0$ ($(3.62)_7$, Remark 3.15).
#
# The pointwise $\sigma_n$ of the fine edges is *not* constrained: the $RT_0$ normal trace
# of PEERS oscillates on the fine scale, and only its hat moments enter (3.62). A node is
# in **separation** where $\lambda_n > 0$ (gap open), in **slip** where $|\nu| = 1$ on an
# $\hat h$ edge under its hat, else in **stick**. `post.friction_diagnostics` classifies
# them.


# %%
def signed_friction_work(solution):
    """q = Q_F lambda_t per h^ edge, and where it is not zero (slip) beyond round-off."""
    fr = build_friction_forms(solution.problem)
    Q, lam_t = fr.q_matrix(solution.friction_bound), solution.part("lam_t")
    q = Q @ lam_t
    # q_j = 0 in stick, and round-off where F itself is round-off (separated edges)
    return q, (np.abs(q) > 1e-4 * (Q @ np.abs(lam_t))) & (np.abs(q) > 1e-6 * np.abs(q).max())


def discrete_conditions(solution) -> dict:
    """The sign, complementarity and friction conditions of (3.62), relative to their scale."""
    pb = solution.problem
    fr = build_friction_forms(pb)
    sigma = solution.x[pb.sigma]
    t_n = pb.block(pb.sigma, pb.lam_n).T @ sigma                 # int sigma_n mu_i
    t_t = pb.block(pb.sigma, pb.index("lam_t")).T @ sigma        # int sigma_t mu_i
    lam_n, lam_t = solution.part("lam_n"), solution.part("lam_t")
    Q = fr.q_matrix(solution.friction_bound)
    bound = Q.T @ np.ones(fr.n_nu)                               # int F mu_i
    q, slipping = signed_friction_work(solution)
    scale_n, scale_lam = np.max(np.abs(t_n)), np.max(np.abs(np.r_[lam_n, lam_t]))
    return {
        "lam_n_min": float(lam_n.min() / scale_lam),
        "sigma_n_max": float(t_n.max() / scale_n),
        "complementarity": float(np.max(np.abs(lam_n * t_n)) / (scale_n * scale_lam)),
        "cone_excess": float(np.max(np.abs(t_t) - bound) / bound.max()),
        "tangential": float(np.max(np.abs(t_t - Q.T @ solution.nu)) / bound.max()),
        "nu_max": float(np.max(np.abs(solution.nu))),
        "slipping_edges": int(slipping.sum()),
        "nu_sign_mismatch": float(np.max(np.abs(solution.nu - np.sign(q))[slipping],
                                         initial=0.0)),
    }


conditions = {"tresca": discrete_conditions(tresca_runs["friction-outer"]),
              "coulomb": discrete_conditions(coulomb_solution)}
for law, values in conditions.items():
    print(f"{law:8s}", {k: (f"{v:.1e}" if isinstance(v, float) else v) for k, v in values.items()})
summaries = {"tresca": post.contact_summary(tresca_runs["friction-outer"]),
             "coulomb": post.contact_summary(coulomb_solution)}
for law, summary in summaries.items():
    print(f"{law:8s} h~ nodes in contact {summary['nodes_in_contact']} (stick "
          f"{summary['stick_nodes']}, slip {summary['slip_nodes']}), total force "
          f"F_abs = {summary['F_abs']:.1f}")

# %% [markdown]
# Along $\Gamma_C$: the hat-averaged stresses (markers) against the bound
# $\pm\mathcal{F}$, the sign $\nu$, and the multipliers with the status of every
# $\tilde h$ node. $\nu = \pm 1$ where the body slips, with the sign of
# $\lambda_t = -u_t$ (Fig. 3.21(b)); in the stick zone $\lambda_t \approx 0$ and
# $\nu = \sigma_t/\mathcal{F}$ lies strictly inside $(-1, 1)$ (3.43). Tresca's bound acts
# even where the body does not touch the foundation, a known weakness of the model;
# Coulomb's $\mathcal{F} = \mu_f|\sigma_n|$ vanishes there.

# %%
STATUS_COLOURS = {"separation": "0.6", "stick": "tab:blue", "slip": "tab:red"}


def plot_zones(solution, title: str, path) -> None:
    pb = solution.problem
    fr = build_friction_forms(pb)
    diag = post.friction_diagnostics(solution)
    hat_length = fr.midpoint_hats.T @ fr.lengths                 # int mu_i ds
    x_fine, x_node = fr.midpoints[:, 0], diag.node_xy[:, 0]
    order = np.argsort(x_fine)
    fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    ax = axes[0]
    ax.plot(x_fine[order], (fr.T_n @ solution.x)[order], drawstyle="steps-mid", lw=0.7,
            color="0.6", label=r"$\sigma_n$ on fine edges")
    ax.plot(x_node, diag.t_n / hat_length, "o", color="k", ms=4, label=r"hat mean of $\sigma_n$")
    ax.plot(x_node, diag.t_t / hat_length, "s", color="tab:green", ms=4,
            label=r"hat mean of $\sigma_t$")
    F = solution.friction_bound[order]
    ax.plot(x_fine[order], F, "r-", drawstyle="steps-mid", lw=1, label=r"$\pm\mathcal{F}$")
    ax.plot(x_fine[order], -F, "r-", drawstyle="steps-mid", lw=1)
    scale = 1.3 * np.max(np.abs(diag.t_n / hat_length))
    ax.set_ylim(-scale, scale)
    ax.set_ylabel("stress")
    ax.legend(fontsize=7, ncol=2)
    ax = axes[1]
    ax.plot(x_fine[order], solution.nu[fr.edge_of][order], drawstyle="steps-mid",
            label=r"$\nu$ (per $\hat h$ edge)")
    _, slipping = signed_friction_work(solution)
    ax.plot(diag.edge_xy[slipping, 0], diag.sign_lam_t[slipping], "kx",
            label=r"sign$(Q_\mathcal{F}\lambda_t)$ where $\neq 0$")
    ax.set_ylim(-1.2, 1.2)
    ax.set_ylabel(r"$\nu$")
    ax.legend(fontsize=7)
    ax = axes[2]
    ax.plot(x_node, diag.lam_n, "k-", lw=0.8, label=r"$\lambda_n$ (gap left)")
    ax.plot(x_node, diag.lam_t, "-", color="tab:green", lw=0.8, label=r"$\lambda_t = -u_t$")
    for status, colour in STATUS_COLOURS.items():
        chosen = diag.node_status == status
        ax.plot(x_node[chosen], diag.lam_t[chosen], "o", color=colour, ms=5, label=status)
    ax.set_xlabel(r"$x_1$ on $\Gamma_C$")
    ax.set_ylabel("displacement")
    ax.legend(fontsize=7, ncol=2)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    save_figure(fig, path)


plot_zones(tresca_runs["friction-outer"], f"Tresca, F = 100, level {LEVEL}",
           OUT / "zones_tresca.png")
plot_zones(coulomb_solution, f"Coulomb, mu_f = {mu_f}, level {LEVEL}", OUT / "zones_coulomb.png")

# %% [markdown]
# The stress in the body under Coulomb friction (von Mises; the corners where $\Gamma_D$
# meets $\Gamma_C$ are singular, so the colour scale is clipped at the 97th percentile, as
# stated on the colour bar). In a notebook the webgui view follows.

# %%
sigma_c = nd.fields(coulomb_solution).sigma
save_figure(plot_von_mises(problem_c.fes.mesh, sigma_c, coulomb.material.nu,
                           f"Coulomb, mu_f = {mu_f}: von Mises stress, level {LEVEL}"),
            OUT / "von_mises_coulomb.png")
draw(post.von_mises(sigma_c, coulomb.material.nu), problem_c.fes.mesh, "von_mises")

# %%
results = {
    "quick": QUICK, "level": LEVEL, "mu_f": mu_f,
    "box_projection_qp_difference": box_qp_difference,
    "iterations": {law: {order: runs[order].iterations for order in LOOP_ORDERS}
                   for law, runs in (("tresca", tresca_runs), ("coulomb", coulomb_runs))},
    "converged": {law: all(runs[o].converged for o in LOOP_ORDERS)
                  for law, runs in (("tresca", tresca_runs), ("coulomb", coulomb_runs))},
    "loop_order_difference": loop_order_difference,
    "agreement": agreement,
    "active_set_difference": active_set_difference,
    "qp_fixed_point_history": qp_coulomb.history,
    "fixed_point_residual": fixed_point_residual,
    "conditions": conditions,
    "summaries": summaries,
}
print(f"wrote {save_results('04_friction', results)}")

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/04_friction_solutions.py`.
#
# 1. **Step lengths.** For Coulomb friction on level 3, count the outer and inner
#    iterations of both loop orders for $\rho_1 \in \{0.5, 1, 1.5\}$ and
#    $\rho_2 \in \{0.25, 0.5, 1, 1.5\}$ (cf. Fig. 3.23). Which loop order is cheaper,
#    counted in inner iterations (each is one solve)? What happens for $\rho_2 = 2.5$,
#    beyond the bound of Theorem 3.42?
# 2. **The friction coefficient.** Solve the Coulomb scene for
#    $\mu_f \in \{0, 0.1, 0.25, 0.5, 1\}$ (`friction.mu`). How do the numbers of stick and
#    slip nodes and the total force
#    $F_{\mathrm{abs}} = \int_{A_C}|\sigma_n| + |\sigma_t|\,ds$ change? Check that
#    $\mu_f = 0$ reproduces the frictionless Uzawa solution of Tutorial 3.
