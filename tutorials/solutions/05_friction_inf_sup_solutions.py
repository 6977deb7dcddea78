# %% [markdown]
# # Solutions to Tutorial 5: Why ĥ = 2h̃: the inf-sup condition of the friction multiplier
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

nested_uzawa = nd.solvers.nested.nested_uzawa             # Algorithm 3.41
NestedUzawaSettings = nd.solvers.NestedUzawaSettings      # its two step lengths, loop order

lesson = nd.Lesson("05_friction_inf_sup_solutions")
QUICK = lesson.quick
GAP_ABS_LEVEL = 3 if QUICK else 4
KERNEL_LEVEL = 2

# %% [markdown]
# ## Exercise 1: $\hat h = \tilde h$ when (3.73) holds
#
# With $g = |x_1|$ the body touches only around $x_1 = 0$, far from the ends of
# $\Gamma_C$: $\mathcal{F} = 0$ near $\partial\Gamma_C$, the hats next to the ends of
# $A_C$ pin the checkerboard mode, and the inf-sup condition (3.74) holds with
# $\hat h = \tilde h$ (Lemma 3.31). Both choices converge, and $\lambda_n$, $\lambda_t$
# agree up to the discretisation difference of $\nu$ (Figs. 3.26-3.27). $\nu$ itself is a
# different function on the two $\hat h$ meshes; it is printed on
# $A_C = \operatorname{supp}\mathcal{F}$ only (elsewhere $\mathcal{F}$ is zero up to
# round-off and $\nu$ does not enter (3.62)).

# %%
gap_abs = {}
for factor in (1, 2):
    scene = nd.load_scene("thesis-3.46-coulomb-gap-abs", [f"contact.hhat_factor={factor}"])
    gap_abs[factor] = nested_uzawa(nd.assemble(scene, nd.build_mesh(scene.geometry, GAP_ABS_LEVEL)),
                                   NestedUzawaSettings.from_scene(scene, eps2=1e-8))
a, b = gap_abs[1], gap_abs[2]
scale = max(np.linalg.norm(b.part("lam_n")), np.linalg.norm(b.part("lam_t")))
gap_abs_difference = {name: float(np.linalg.norm(a.part(name) - b.part(name)) / scale)
                      for name in ("lam_n", "lam_t")}
for factor, solution in gap_abs.items():
    forms = nd.friction_forms(solution.problem)
    F_hat = forms.per_hat_edge(solution.friction_bound)
    on_a_c = (F_hat > 1e-6 * F_hat.max())[forms.edge_of]
    print(f"h^ = {factor} h~: {solution.iterations}, converged {solution.converged}; "
          f"nu on the fine edges of A_C: {np.round(solution.nu[forms.edge_of][on_a_c], 2)}")
print(f"difference of the multipliers (relative): {gap_abs_difference}")

fig, ax = plt.subplots(figsize=(8, 3.5))
for (factor, solution), style in zip(gap_abs.items(), ("s--", "o-")):
    traces = nd.contact_traces(solution)
    order = np.argsort(traces.coarse_xy[:, 0])
    ax.plot(traces.coarse_xy[order, 0], traces.coarse_lam_t[order], style, ms=3,
            label=f"$\\lambda_t$, ĥ = {factor}h̃" if factor > 1 else "$\\lambda_t$, ĥ = h̃")
ax.set_xlabel(r"$x_1$ on $\Gamma_C$")
ax.set_ylabel(r"$\lambda_t = -u_t$")
ax.set_title(f"g = |x₁|, level {GAP_ABS_LEVEL}: both ĥ give the same λ_t")
ax.grid(alpha=0.3)
ax.legend()
lesson.save(fig, "gap_abs_lambda_t")

# %% [markdown]
# ## Exercise 2: a variable friction bound
#
# With $\hat h = \tilde h$ there are $N_A = N_C + 1$ values of $\nu$ and only $N_C$ hats,
# whatever $\mathcal{F}$: $Q_{\mathcal{F}}^\top$ maps $\mathbb{R}^{N_A}$ to
# $\mathbb{R}^{N_C}$ and has a kernel for *every* $\mathcal{F} > 0$ on $\Gamma_C$. What
# $\mathcal{F}$ changes is its shape:
#
# $$
# (Q_{\mathcal{F}}^\top\kappa)_i = \sum_j \kappa_j \int_{e_j} \mathcal{F}\mu_i\,ds = 0
# \quad\Longrightarrow\quad \kappa_{j+1} = -\kappa_j\,\frac{w_j}{w_{j+1}}
# $$
#
# with the $\mathcal{F}$-weights $w_j$ of the two halves of the hat, so the signs still
# alternate but the magnitudes follow $\mathcal{F}$: a *weighted* checkerboard. Only
# $\mathcal{F} = 0$ near the ends (3.73) helps.

# %%
def kernel_of(problem, F) -> np.ndarray:
    fr = nd.friction_forms(problem)
    Q = fr.q_matrix(F).toarray()
    vector = np.linalg.svd(Q.T)[2][-1]
    residual = np.linalg.norm(Q.T @ vector)
    assert Q.shape[0] == Q.shape[1] + 1 and residual < 1e-10 * np.abs(Q).max()
    return vector / np.max(np.abs(vector)), fr


scene = nd.load_scene("thesis-3.46-coulomb-gap0", ["contact.hhat_factor=1"])
problem = nd.assemble(scene, nd.build_mesh(scene.geometry, KERNEL_LEVEL))
fr = nd.friction_forms(problem)
F_variable = 1.0 + fr.midpoints[:, 0] ** 2
kernel_constant, _ = kernel_of(problem, np.ones(len(fr.lengths)))
kernel_variable, _ = kernel_of(problem, F_variable)
kernel_variable *= np.sign(kernel_variable[0])
alternates = bool(np.all(np.sign(kernel_variable[1:]) == -np.sign(kernel_variable[:-1])))
print(f"F = 1 + x^2, level {KERNEL_LEVEL}: signs alternate {alternates}, |kappa| from "
      f"{np.abs(kernel_variable).min():.3f} to {np.abs(kernel_variable).max():.3f}")

fig, ax = plt.subplots(figsize=(8, 3.2))
ax.plot(kernel_constant * np.sign(kernel_constant[0]), "s--", label=r"$\mathcal{F} = 1$")
ax.plot(kernel_variable, "o-", label=r"$\mathcal{F} = 1 + x_1^2$")
ax.set_xlabel("ĥ edge j along Γ_C")
ax.set_ylabel(r"kernel vector $\kappa_j$ (scaled)")
ax.set_title("The kernel of $Q_\\mathcal{F}^T$ for ĥ = h̃: a weighted checkerboard")
ax.grid(alpha=0.3)
ax.legend()
lesson.save(fig, "kernel_variable_F")

# %%
lesson.results({"gap_abs_converged": [s.converged for s in gap_abs.values()],
                "gap_abs_difference": gap_abs_difference,
                "kernel_alternates": alternates,
                "kernel_spread": float(np.abs(kernel_variable).max()
                                       / np.abs(kernel_variable).min())})
