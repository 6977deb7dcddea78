# %% [markdown]
# # Tutorial 5: Why ĥ = 2h̃: the inf-sup condition of the friction multiplier
#
# **Run time** on a 2-core laptop: about 8 s; about 7 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 05 --quick`).
#
# **The idea in words.** The friction force is represented by a multiplier that lives on a
# mesh of the contact boundary. If that mesh is as fine as the one of the contact
# multiplier, some patterns of the friction multiplier (a checkerboard of alternating
# signs) are invisible to every stress: the discrete problem is not stable and the
# algorithm struggles. Taking the friction mesh twice as coarse removes those patterns.
# This tutorial computes the stability constant for both choices and shows the kernel and
# its effect on the iteration counts.
#
# **Problem.** Example 3.46 with Coulomb friction and *no* initial gap, $g \equiv 0$: the
# whole of $\Gamma_C$ touches the foundation, so the friction zone
# $A_C = \operatorname{supp}\mathcal{F}$ reaches the ends of $\Gamma_C$. Is the friction
# multiplier $\nu$ of (3.62) (Tutorial 4) then still determined by the discrete problem?
#
# **Discretisation.** PEERS for $(\sigma, u, \eta)$, $P_1$ multipliers $\lambda_t$,
# $\lambda_n$ on the mesh $\tilde h = 2h$ of $\Gamma_C$ (vanishing at the ends of
# $\Gamma_C$), and $\nu$ piecewise constant on a mesh $\hat h$ of $\Gamma_C$;
# $\hat h = \tilde h$ or $\hat h = 2\tilde h$ (`contact.hhat_factor` 1 or 2). $\nu$ enters
# only through $q(\kappa, \mu) = \int_{\Gamma_C} \mathcal{F}\kappa\mu\,ds$, i.e. through
# the matrix $Q_{\mathcal{F}}$ of (3.95).
#
# **What you will learn.**
# 1. A counting argument: with $\hat h = \tilde h$ there is one $\nu$ more than there are
#    hats to test it, so $Q_{\mathcal{F}}^\top$ has a kernel, the checkerboard
#    $\nu = (+1, -1, +1, \dots)$.
# 2. How to compute the discrete inf-sup constant of $q$ (3.72) as a smallest singular
#    value, and that it is bounded below for $\hat h = 2\tilde h$ (Lemma 3.29), or for
#    $\hat h = \tilde h$ when $\mathcal{F}$ vanishes near the ends of $\Gamma_C$
#    (assumption (3.73), Lemma 3.31).
# 3. What the solver sees: without the inf-sup condition the nested Uzawa algorithm
#    needs many more steps or stalls, and its error message names the remedy.
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011: Sections 3.2.2 and 3.3.3:
# eqs. (3.72)-(3.74), (3.95), Lemmas 3.29 and 3.31, Remark 3.30, Algorithm 3.41,
# Example 3.46, Figs. 3.24-3.28. F. Brezzi, M. Fortin, *Mixed and hybrid finite element
# methods*, Springer 1991, Chapter II (discrete inf-sup conditions).

# %% [markdown]
# ## Parameters

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

nested_uzawa = nd.solvers.nested.nested_uzawa             # Algorithm 3.41
NestedUzawaSettings = nd.solvers.NestedUzawaSettings      # its two step lengths, loop order
ConvergenceError = nd.solvers.ConvergenceError            # an algorithm that did not converge
metric_matrix = nd.solvers.projections.metric_matrix      # the metric W of the projection

lesson = nd.Lesson("05_friction_inf_sup")              # figures and results.json go here
QUICK = lesson.quick
GAP0_LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4]  # levels of the g = 0 study

# %% [markdown]
# ## The scene
#
# The $g = 0$ variant of Example 3.46 with Coulomb friction: $\Gamma_D$ the clamped ends,
# $\Gamma_N$ the loaded top, $\Gamma_C$ the bottom, now in contact along its whole length.

# %%
gap0 = {factor: nd.load_scene("thesis-3.46-coulomb-gap0", [f"contact.hhat_factor={factor}"])
        for factor in (1, 2)}
lesson.save(nd.plot_geometry(gap0[2], level=GAP0_LEVELS[0],
                             title=f"Example 3.46, g = 0: boundary parts, level {GAP0_LEVELS[0]}"),
            "geometry")

# %% [markdown]
# ## 1. Counting: why $\hat h = 2\tilde h$
#
# With $g = 0$ the whole of $\Gamma_C$ touches, $A_C = \Gamma_C$, and assumption (3.73)
# ($A_C$ keeps a distance from $\partial\Gamma_C$) fails. Count: $\lambda_t$ vanishes at
# the ends of $\Gamma_C$, so $C_{\tilde h}$ has $N_C$ interior hats, while $L_{\hat h}$
# with $\hat h = \tilde h$ has one $\nu$ per $\tilde h$ edge, $N_A = N_C + 1$. Then
# $Q_{\mathcal{F}}^\top : \mathbb{R}^{N_A} \to \mathbb{R}^{N_C}$ *must* have a kernel. For
# $\mathcal{F} \equiv 1$ it is the checkerboard $\kappa = (+1, -1, +1, \dots)$: every hat
# covers two neighbouring edges of equal length and sees
#
# $$
# \int_{\Gamma_C} \mu_i\kappa\,ds = \frac{\tilde h}{2}\,(\kappa_i + \kappa_{i+1}) = 0 .
# $$
#
# Such a $\nu$ changes nothing in $(3.62)_5$, so $\nu$ is not unique and the discrete
# inf-sup condition (3.74) fails. With $\hat h = 2\tilde h$ every $\hat h$ edge has an
# $\tilde h$ node in its middle whose hat lies inside it (proof of Lemma 3.29); the
# constant of (3.72), measured in $W$ ($H^{1/2}$ on $C_{\tilde h}$) and
# $\|\kappa\|^2_{-1/2,\hat h} = \hat h\,\|\kappa\|^2_{L^2}$ (Remark 3.30), is then the
# smallest singular value of $(\hat h M)^{-1/2} Q_{\mathcal{F}} W^{-1/2}$.


# %%
def inf_sup(problem, F=None) -> dict:
    """Discrete inf-sup constant of q (3.72) for F (default 1 on Gamma_C), and the kernel."""
    fr = nd.friction_forms(problem)
    F = np.ones(len(fr.lengths)) if F is None else F
    rows = fr.per_hat_edge(F) > 0                                # the h^ edges of A_C
    Q = fr.q_matrix(F).toarray()[rows]
    W = metric_matrix(problem.spaces.contact, 2.0, "h12")        # ||mu||^2 ~ mu^T W mu
    values, vectors = np.linalg.eigh(W)
    W_inv_root = (vectors / np.sqrt(values)) @ vectors.T
    scaled = (Q / fr.hat_lengths[rows, None]) @ W_inv_root
    singular = np.linalg.svd(scaled, compute_uv=False)
    n_a, n_c = Q.shape
    kernel = np.linalg.svd(Q.T)[2][-1] if n_a > n_c else np.zeros(n_a)
    return {"N_A": n_a, "N_C": n_c, "beta": float(singular[-1]) if n_a <= n_c else 0.0,
            "kernel": np.round(kernel / (np.max(np.abs(kernel)) or 1.0), 6).tolist()}


inf_sup_rows = []
for level in GAP0_LEVELS:
    row = {"level": level}
    for factor, scene in gap0.items():
        row[factor] = inf_sup(nd.assemble(scene, nd.build_mesh(scene.geometry, level)))
    inf_sup_rows.append(row)
    print(f"level {level}: h^ = h~: N_A = {row[1]['N_A']:3d} > N_C = {row[1]['N_C']:3d}, "
          f"beta = 0; h^ = 2h~: N_A = {row[2]['N_A']:3d}, beta = {row[2]['beta']:.4f}")
print("kernel of Q_F^T for h^ = h~ on level 1:", inf_sup_rows[0][1]["kernel"])

# %% [markdown]
# A picture of the kernel on level 1: every hat $\mu_i$ of $C_{\tilde h}$ covers two
# $\hat h = \tilde h$ edges of equal length with opposite $\nu$, so
# $\int \mathcal{F}\mu_i\nu\,ds = 0$ for all $i$.

# %%
kernel = np.array(inf_sup_rows[0][1]["kernel"])
problem_1 = nd.assemble(gap0[1], nd.build_mesh(gap0[1].geometry, GAP0_LEVELS[0]))
fr_1 = nd.friction_forms(problem_1)
ends = np.sort(np.unique(np.round(np.r_[fr_1.midpoints[:, 0] - fr_1.lengths / 2,
                                        fr_1.midpoints[:, 0] + fr_1.lengths / 2], 12)))
hat_ends = ends[::2]                                    # the h~ nodes (every other fine node)
fig, ax = plt.subplots(figsize=(9, 3.2))
ax.stairs(kernel, hat_ends, lw=2, label=r"kernel of $Q_\mathcal{F}^T$: $\nu$ per $\hat h$ edge")
for left, middle, right in zip(hat_ends[:-2], hat_ends[1:-1], hat_ends[2:]):
    ax.plot([left, middle, right], [0, 0.8, 0], color="0.6", lw=0.8)
ax.plot([], [], color="0.6", lw=0.8, label=r"hats $\mu_i$ of $C_{\tilde h}$ (scaled)")
ax.set_xlabel(r"$x_1$ on $\Gamma_C$")
ax.set_ylabel(r"$\nu$")
ax.set_ylim(-1.4, 1.4)
ax.set_title(r"$\hat h = \tilde h$, $\mathcal{F} \equiv 1$: the checkerboard $\nu$ no hat can see")
ax.legend(fontsize=8, loc="lower right")
ax.grid(alpha=0.3)
lesson.save(fig, "checkerboard")

# %% [markdown]
# $\beta$ stays the same on every level for $\hat h = 2\tilde h$ (in the mesh-dependent
# norm of Lemma 3.29). If instead $\mathcal{F}$ vanishes near the ends of $\Gamma_C$
# (assumption (3.73)), the hats next to the ends of $A_C$ pin the checkerboard and
# $\hat h = \tilde h$ is fine (Lemma 3.31):

# %%
scene = gap0[1]
problem_inner = nd.assemble(scene, nd.build_mesh(scene.geometry, GAP0_LEVELS[-1]))
fr_inner = nd.friction_forms(problem_inner)
inner = inf_sup(problem_inner, (np.abs(fr_inner.midpoints[:, 0]) < 1.5).astype(float))
print(f"h^ = h~, F = 1 on |x1| < 1.5 only: N_A = {inner['N_A']} <= N_C = {inner['N_C']}, "
      f"beta = {inner['beta']:.3f}")

# %% [markdown]
# ## 2. What the solver sees
#
# What the solver sees: the nested Uzawa iteration on the $g = 0$ scene with both
# choices. With $\hat h = \tilde h$ it needs many more outer steps where it converges at
# all, and on some levels it stalls: then `nested_uzawa` raises `ConvergenceError`, whose
# message names the remedy `contact.hhat_factor = 2`.

# %%
gap0_runs = {1: [], 2: []}
failure_messages = []
for level in GAP0_LEVELS:
    for factor, scene in gap0.items():
        problem = nd.assemble(scene, nd.build_mesh(scene.geometry, level))
        try:
            solution = nested_uzawa(problem, NestedUzawaSettings.from_scene(scene))
            gap0_runs[factor].append({"level": level, "outer": solution.iterations["outer"],
                                      "inner": solution.iterations["inner"],
                                      "converged": solution.converged})
        except ConvergenceError as error:
            failure_messages.append(f"level {level}, h^ = {factor} h~: {error}")
            gap0_runs[factor].append({"level": level, "outer": len(error.history),
                                      "inner": None, "converged": False})
    print(f"level {level}: outer iterations h^ = h~: {gap0_runs[1][-1]['outer']:5d} "
          f"(converged {gap0_runs[1][-1]['converged']}), h^ = 2h~: "
          f"{gap0_runs[2][-1]['outer']:4d} (converged {gap0_runs[2][-1]['converged']})")
for message in failure_messages:
    print(message)

fig, ax = plt.subplots(figsize=(6, 4))
for factor, marker in ((1, "s--"), (2, "o-")):
    rows = gap0_runs[factor]
    ax.semilogy([r["level"] for r in rows], [r["outer"] for r in rows], marker,
                label=f"ĥ = {factor}h̃" if factor > 1 else "ĥ = h̃")
    failed = [r for r in rows if not r["converged"]]
    ax.semilogy([r["level"] for r in failed], [r["outer"] for r in failed], "rx", ms=12)
ax.set_xlabel("level")
ax.set_ylabel("outer iterations (x: ConvergenceError)")
ax.set_xticks(GAP0_LEVELS)
ax.set_title("Coulomb, g = 0: nested Uzawa")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
lesson.save(fig, "gap0_iterations")

# %%
lesson.results({
    "inf_sup": [{"level": r["level"], "hhat_h": {k: r[1][k] for k in ("N_A", "N_C", "beta")},
                 "hhat_2h": {k: r[2][k] for k in ("N_A", "N_C", "beta")},
                 "kernel_hhat_h": r[1]["kernel"]} for r in inf_sup_rows],
    "inf_sup_inner": {k: inner[k] for k in ("N_A", "N_C", "beta")},
    "gap0": {"hhat_h": gap0_runs[1], "hhat_2h": gap0_runs[2]},
    "failure_messages": failure_messages,
})

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/05_friction_inf_sup_solutions.py`.
#
# 1. **$\hat h = \tilde h$ is fine under (3.73).** Solve `thesis-3.46-coulomb-gap-abs`
#    ($g = |x_1|$) with `contact.hhat_factor` 1 and 2 on level 4 and compare $\lambda_n$,
#    $\lambda_t$ and $\nu$ (Figs. 3.26-3.28). Why do both converge here, unlike for
#    $g = 0$?
# 2. **A variable friction bound.** Compute the kernel of $Q_{\mathcal{F}}^\top$ for
#    $\hat h = \tilde h$ and $\mathcal{F} = 1 + x_1^2$ (`inf_sup(problem, F)` above) on
#    level 2. Is it still a checkerboard? Why can no choice of $\mathcal{F} > 0$ on all of
#    $\Gamma_C$ remove the kernel?
