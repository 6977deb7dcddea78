# %% [markdown]
# # Tutorial 4: Tresca and Coulomb friction, the nested Uzawa algorithm
#
# **Run time** on a 2-core laptop: about 11 s; about 9 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 04 --quick`).
#
# **The idea in words.** Friction resists sliding along the contact boundary: a point
# sticks as long as the tangential traction stays below a bound, and slides (slips) once
# it reaches it, then opposite to its motion. With Tresca friction the bound is given;
# with Coulomb friction it is the friction coefficient times the contact pressure, which
# is itself unknown. The nested Uzawa algorithm handles this with two loops: an inner loop
# for the contact (as in Tutorial 3) and an outer loop that updates the direction and the
# bound of the friction force, until both settle. The pictures show the contact traces
# with their stick and slip zones and how the loops converge.
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
# with $|\nu| \le 1$ (why $\hat h = 2\tilde h$: Tutorial 5): the discrete variational
# inequality (3.62) with $q(\kappa, \mu) = \int_{\Gamma_C} \mathcal{F}\kappa\mu\,ds$.
#
# **What you will learn.** How Algorithm 3.41 solves frictional contact: an inner Uzawa loop
# for $\lambda_n$ (Tutorial 3) inside an outer projected-gradient loop for $\nu$, or the
# loops exchanged (Remark 3.43); how Coulomb's bound $\mathcal{F} = \mu_f|\sigma_n|$
# becomes a fixed point inside the same outer loop (Remark 3.45); and how to read stick,
# slip and separation on $\Gamma_C$ from the result.
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

nested_uzawa = nd.solvers.nested.nested_uzawa             # Algorithm 3.41
NestedUzawaSettings = nd.solvers.NestedUzawaSettings      # its two step lengths, loop order
Model = nd.solvers.Model                                  # the law and moduli the QPs need
solve_qp_friction = nd.solvers.qp.solve_qp_friction       # friction as a sequence of QPs

lesson = nd.Lesson("04_friction")                   # figures and results.json go here
QUICK = lesson.quick
STRESS = ("r1", "r2", "b1", "b2")   # the stress unknowns: two RT0 rows, two Curl bubbles
LEVEL = 3 if QUICK else 4                        # mesh level of Example 3.46
LOOP_ORDERS = ["friction-outer", "contact-outer"]  # Algorithm 3.41 and Remark 3.43
EPS1, EPS2 = 1e-10, 1e-9                         # tight tolerances, to compare with the QP

# %% [markdown]
# ## The scene and the answer
#
# $\Gamma_D$ the clamped ends, $\Gamma_N$ the loaded top, $\Gamma_C$ the bottom above the
# foundation. The answer first, from `nd.solve` (ngdual's default solver): the pressure
# $p_h$ and the shear $q_h$ on $\Gamma_C$ with the zones where the body sticks (green) and
# slips (orange). The solve warns because the thesis' scene forces $u_n = g$ at the clamped
# corners (`ends = "thesis"`, kept to reproduce its tables).

# %%
tresca = nd.load_scene("thesis-3.46-tresca")
coulomb = nd.load_scene("thesis-3.46-coulomb")
mu_f = coulomb.friction.mu
lesson.save(nd.plot_geometry(coulomb, level=LEVEL), "geometry")
default = nd.solve(coulomb, LEVEL)
lesson.save(nd.plot_contact_traces(nd.contact_traces(default), f"Coulomb, mu_f = {mu_f}, "
                                   f"level {LEVEL}: {default.method}"), "traces_coulomb")

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
problem_t = nd.assemble(tresca, nd.build_mesh(tresca.geometry, LEVEL))
problem_c = nd.assemble(coulomb, nd.build_mesh(coulomb.geometry, LEVEL))
forms = nd.friction_forms(problem_t)
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
#   a projected gradient step for $\nu$. $P^\Lambda$ is a QP in the mass matrix of
#   $L_{\hat h}$ (Remark 3.44); $\nu$ is piecewise constant, that matrix diagonal, and the
#   QP is the clipping $\operatorname{clip}(b/M, -1, 1)$, unlike $P^+$ in Tutorial 3.
#
# With the loops exchanged (Remark 3.43, `"contact-outer"`) the cheap $\nu$ iteration runs
# inside. $\rho_2$ is relative to the computed stability bound of the $\nu$ step, so
# $0 < \rho_2 < 2$ converges for any $E$ and load. A run stops when the increments *and*
# the residual of $\nu\lambda_t = |\lambda_t|$ are below $\varepsilon_2$.

# %%
def relative(a, b) -> float:
    return float(np.linalg.norm(a - b) / (np.linalg.norm(b) or 1.0))


def run_both_orders(problem, scene) -> dict:
    """nested_uzawa in both loop orders, with their iteration counts printed."""
    runs = {order: nested_uzawa(problem, NestedUzawaSettings.from_scene(
                scene, eps1=EPS1, eps2=EPS2, loop_order=order)) for order in LOOP_ORDERS}
    for order, solution in runs.items():
        print(f"{scene.friction.law}, {order:14s}: {solution.iterations['outer']:4d} outer, "
              f"{solution.iterations['inner']:5d} inner, converged {solution.converged}")
    return runs


tresca_runs = run_both_orders(problem_t, tresca)
loop_order_difference = {"tresca": relative(*(tresca_runs[o].x for o in LOOP_ORDERS))}
print(f"the two loop orders differ by {loop_order_difference['tresca']:.1e} (relative)")

# %% [markdown]
# Both reach the same discrete solution: (3.62) has a unique $\sigma$, and with
# $\hat h = 2\tilde h$ a unique $\nu$ (Tutorial 5).
#
# ## 3. Coulomb friction: a fixed point on $\mathcal{F}$
#
# Coulomb's bound depends on the solution, $\mathcal{F} = \mu_f|\sigma_n|$: a
# quasi-variational inequality. Remark 3.45 updates $\mathcal{F}$ *inside* the outer loop,
# before each $\nu$ step (steps 8'-10'), starting from the frictionless solution; (3.123)
# averages $|\sigma_n|$ over every $\hat h$ edge (`forms.coulomb_bound_of`). At convergence
# $\mathcal{F}$ is a fixed point: recomputed from the final $\sigma_n$ it is the bound the
# solution was computed with.

# %%
coulomb_runs = run_both_orders(problem_c, coulomb)
loop_order_difference["coulomb"] = relative(*(coulomb_runs[o].x for o in LOOP_ORDERS))
coulomb_solution = coulomb_runs["friction-outer"]
forms_c = nd.friction_forms(problem_c)
F_again = forms_c.coulomb_bound_of(forms_c.T_n @ coulomb_solution.x, mu_f)
fixed_point_residual = float(np.max(np.abs(F_again - coulomb_solution.friction_bound))
                             / np.max(coulomb_solution.friction_bound))
print(f"max |F(sigma_n) - F| / max F = {fixed_point_residual:.1e}")

# %% [markdown]
# ## 4. Independent checks
#
# For a *given* $\mathcal{F}$, (3.62) is the KKT system of one QP in $(\sigma, \nu)$:
# minimise $\tfrac12\sigma^\top A\sigma - g^\top\sigma$ subject to
# $B^\top\sigma - (0, 0, 0, Q_{\mathcal{F}}^\top\nu) = b$, $C_n^\top\sigma \le 0$,
# $|\nu_j| \le 1$. `solve_qp_friction` hands it to Clarabel, for Coulomb inside a third
# loop of successive substitution on $\mathcal{F}$. It shares only the matrices with the
# nested Uzawa loops; ngdual's default solver (the picture above, a semismooth Newton
# method condensed onto $\Gamma_C$) shares even less.


# %%
def compare(nested, other) -> dict:
    """Relative differences of sigma, lambda_t, lambda_n and nu (where F matters)."""
    fr = nd.friction_forms(other.problem)
    lam_scale = max(np.linalg.norm(other.part("lam_n")), np.linalg.norm(other.part("lam_t")))
    F_hat = fr.per_hat_edge(other.friction_bound)
    return {"sigma": relative(nested.part(*STRESS), other.part(*STRESS)),
            "lam_t": relative(nested.part("lam_t"), other.part("lam_t")),
            "lam_n": float(np.linalg.norm(nested.part("lam_n") - other.part("lam_n")) / lam_scale),
            "nu": float(np.max(np.abs(nested.nu - other.nu)[F_hat > 1e-3 * F_hat.max()]))}


qp_coulomb = solve_qp_friction(problem_c, Model.of(coulomb))
agreement = {"tresca": compare(tresca_runs["friction-outer"],
                               solve_qp_friction(problem_t, Model.of(tresca))),
             "coulomb": compare(coulomb_solution, qp_coulomb)}
active_set_difference = compare(coulomb_solution, default)
for name, values in (*agreement.items(), (default.method, active_set_difference)):
    print(f"nested Uzawa vs {name:10s}", {k: f"{v:.1e}" for k, v in values.items()})

fig, ax = plt.subplots(figsize=(7, 4))
for (law, runs) in (("Tresca", tresca_runs), ("Coulomb", coulomb_runs)):
    for order, style in zip(LOOP_ORDERS, ("-", "--")):
        history = np.array(runs[order].history)
        steps = np.arange(1, len(history) + 1)
        # an exact 0: nu saturated at +-1 on every edge, the projection fixes it for good
        ax.semilogy(steps[history > 0], history[history > 0], style, label=f"{law}, {order}")
ax.semilogy(range(1, len(qp_coulomb.history) + 1), qp_coulomb.history, "k:o", ms=3,
            label="Coulomb, QP on F (3rd loop)")
ax.set(xlabel="outer iteration", ylabel="outer residual / change of F",
       title=f"Nested Uzawa on Example 3.46, level {LEVEL}")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
lesson.save(fig, "outer_histories")

# %% [markdown]
# ## 5. Stick, slip and separation on $\Gamma_C$
#
# What the discrete solution satisfies, tested with the $\tilde h$ hats $\mu_i$
# (Proposition 3.25): $\lambda_n \ge 0$, $\int\sigma_n\mu_i \le 0$ and their product
# zero; $|\int\sigma_t\mu_i| \le \int\mathcal{F}\mu_i$ (the friction cone, tested) with
# $\int\sigma_t\mu_i = q(\mu_i, \nu)$; $|\nu| \le 1$ and
# $\nu = \operatorname{sign}(Q_{\mathcal{F}}\lambda_t)$ wherever
# $Q_{\mathcal{F}}\lambda_t \ne 0$ ($(3.62)_7$). A node *separates* where $\lambda_n > 0$,
# *slips* where $|\nu| = 1$ under its hat, else it *sticks*; in the stick zone
# $\nu = \sigma_t/\mathcal{F}$ lies strictly inside $(-1, 1)$ (3.43). The pointwise
# $\sigma_n$ of the fine edges is not constrained: only its hat moments enter (3.62).
# Tresca's bound $\mathcal{F} = 100$ acts even where the body does not touch the
# foundation, a known weakness of the model; Coulomb's $\mu_f|\sigma_n|$ vanishes there.


# %%
def discrete_conditions(solution) -> dict:
    """The sign, complementarity and friction conditions of (3.62), relative to their scale."""
    pb = solution.problem
    fr = nd.friction_forms(pb)
    sigma = solution.x[pb.sigma]
    t_n = pb.block(pb.sigma, pb.lam_n).T @ sigma                 # int sigma_n mu_i
    t_t = pb.block(pb.sigma, pb.index("lam_t")).T @ sigma        # int sigma_t mu_i
    lam_n, lam_t = solution.part("lam_n"), solution.part("lam_t")
    Q = fr.q_matrix(solution.friction_bound)
    bound = Q.T @ np.ones(fr.n_nu)                               # int F mu_i
    q = Q @ lam_t                        # 0 in stick; round-off where F is (separated edges)
    slipping = (np.abs(q) > 1e-4 * (Q @ np.abs(lam_t))) & (np.abs(q) > 1e-6 * np.abs(q).max())
    scale_n, scale_lam = np.max(np.abs(t_n)), np.max(np.abs(np.r_[lam_n, lam_t]))
    return {"lam_n_min": float(lam_n.min() / scale_lam),
            "sigma_n_max": float(t_n.max() / scale_n),
            "complementarity": float(np.max(np.abs(lam_n * t_n)) / (scale_n * scale_lam)),
            "cone_excess": float(np.max(np.abs(t_t) - bound) / bound.max()),
            "tangential": float(np.max(np.abs(t_t - Q.T @ solution.nu)) / bound.max()),
            "nu_max": float(np.max(np.abs(solution.nu))),
            "slipping_edges": int(slipping.sum()),
            "nu_sign_mismatch": float(np.max(np.abs(solution.nu - np.sign(q))[slipping],
                                             initial=0.0))}


conditions = {"tresca": discrete_conditions(tresca_runs["friction-outer"]),
              "coulomb": discrete_conditions(coulomb_solution)}
for law, values in conditions.items():
    print(f"{law:8s}", {k: (f"{v:.1e}" if isinstance(v, float) else v) for k, v in values.items()})
lesson.save(nd.plot_contact_traces(nd.contact_traces(tresca_runs["friction-outer"]),
                                   f"Tresca, F = 100, level {LEVEL}: nested Uzawa"),
            "traces_tresca")

# %%
lesson.results({
    "level": LEVEL, "mu_f": mu_f,
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
})

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
