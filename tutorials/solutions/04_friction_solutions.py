# %% [markdown]
# # Solutions to Tutorial 4: Tresca and Coulomb friction, the nested Uzawa algorithm
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

uzawa = nd.solvers.uzawa.uzawa                            # Algorithm 3.38
nested_uzawa = nd.solvers.nested.nested_uzawa             # Algorithm 3.41
UzawaSettings = nd.solvers.UzawaSettings                  # its step length, metric, tolerance
NestedUzawaSettings = nd.solvers.NestedUzawaSettings      # its two step lengths, loop order
ConvergenceError = nd.solvers.ConvergenceError            # an algorithm that did not converge

lesson = nd.Lesson("04_friction_solutions")
QUICK = lesson.quick
STRESS = ("r1", "r2", "b1", "b2")   # the stress unknowns: two RT0 rows, two Curl bubbles
LEVEL = 3                                             # the first level with a stick zone
RHO1S = [1.0] if QUICK else [0.5, 1.0, 1.5]
RHO2S = [0.5, 1.0, 1.5] if QUICK else [0.25, 0.5, 1.0, 1.5]
LARGE_RHO2S = [2.5, 8.0]
MUS = [0.0, 0.1, 0.5, 1.0] if QUICK else [0.0, 0.1, 0.25, 0.5, 1.0]
coulomb = nd.load_scene("thesis-3.46-coulomb")
problem = nd.assemble(coulomb, nd.build_mesh(coulomb.geometry, LEVEL))


def attempt(**options):
    """(outer, inner, converged) of one nested Uzawa run; ConvergenceError counts as failed."""
    try:
        solution = nested_uzawa(problem, NestedUzawaSettings.from_scene(coulomb, **options))
        return solution.iterations["outer"], solution.iterations["inner"], solution.converged
    except ConvergenceError as error:
        return len(error.history), None, False


# %% [markdown]
# ## Exercise 1: step lengths
#
# With $\nu$ outside (Algorithm 3.41) the number of *outer* steps depends on $\rho_2$
# only, like the contraction factor $1 - c\rho_2$ of a projected gradient method: halving
# $\rho_2$ about doubles it. Each outer step runs a whole inner Uzawa loop, whose length
# depends on $\rho_1$. With the loops exchanged (Remark 3.43) the outer count depends on
# $\rho_1$ and the cheap $\nu$ loop runs inside; counted in inner iterations (= solves
# with the condensed $\Gamma_C$ response) the exchanged order is usually cheaper here.
#
# $\rho_2$ is measured relative to the computed bound $2/\lambda_{\max}(H)$ of the
# *unconstrained* $\nu$ iteration (Theorem 3.42 gives a cruder bound of the same kind).
# Beyond it the iteration may still converge: on slip edges $|\nu| = 1$ is enforced by
# the projection, which is a contraction whatever the step, so only stick edges can be
# excited. Where there is a stick zone, a step far beyond the bound stalls, and
# `nested_uzawa` says so.

# %%
sweep = {}
for order in ("friction-outer", "contact-outer"):
    for rho1 in RHO1S:
        for rho2 in RHO2S:
            sweep[f"{order} {rho1} {rho2}"] = attempt(rho1=rho1, rho2=rho2, loop_order=order)
        print(f"{order:14s} rho1 = {rho1}: (outer, inner) for rho2 = {RHO2S}: "
              f"{[sweep[f'{order} {rho1} {rho2}'][:2] for rho2 in RHO2S]}")
large = {str(rho2): attempt(rho2=rho2, max_iter=600) for rho2 in LARGE_RHO2S}
for rho2, (outer, _, converged) in large.items():
    print(f"rho2 = {rho2}: converged {converged} after {outer} outer steps")

fig, ax = plt.subplots(figsize=(6.5, 4))
for order, style in (("friction-outer", "o-"), ("contact-outer", "s--")):
    for rho1 in RHO1S:
        inner = [sweep[f"{order} {rho1} {rho2}"][1] for rho2 in RHO2S]
        ax.plot(RHO2S, inner, style, label=f"{order}, ρ₁ = {rho1}")
ax.set_xlabel("ρ₂")
ax.set_ylabel("inner iterations (= solves)")
ax.set_title(f"Coulomb, level {LEVEL}: cost of the two loop orders")
ax.grid(alpha=0.3)
ax.legend(fontsize=8)
lesson.save(fig, "step_lengths")

# %% [markdown]
# ## Exercise 2: the friction coefficient
#
# With $\mu_f = 0$ the friction bound vanishes, $\nu$ plays no role and the nested
# algorithm solves the frictionless problem: $\sigma$ agrees with Algorithm 3.38 to the
# solver tolerance. Growing $\mu_f$ adds friction forces, so $F_{\mathrm{abs}}$ grows,
# and the tangential stress can be carried without slip on a growing part of the contact
# zone: the stick zone grows.

# %%
frictionless = nd.load_scene("thesis-3.46-frictionless")
reference = uzawa(nd.assemble(frictionless, nd.build_mesh(frictionless.geometry, LEVEL)),
                  UzawaSettings.from_scene(frictionless, eps=1e-10))
by_mu = {}
for mu in MUS:
    solution = nested_uzawa(problem, NestedUzawaSettings.from_scene(coulomb, mu_f=mu, eps1=1e-10,
                                                                    eps2=1e-9))
    summary = nd.post.contact_summary(solution)
    by_mu[str(mu)] = {"converged": solution.converged, "F_abs": summary["F_abs"],
                      "nodes_in_contact": summary["nodes_in_contact"],
                      "stick_nodes": summary["stick_nodes"], "slip_nodes": summary["slip_nodes"],
                      "sigma_vs_frictionless": float(
                          np.linalg.norm(solution.part(*STRESS)
                                         - reference.part(*STRESS))
                          / np.linalg.norm(reference.part(*STRESS)))}
    row = by_mu[str(mu)]
    # with F = 0 there are no h^ edges in A_C: the stick/slip split is meaningless
    split = (f"stick {row['stick_nodes']}, slip {row['slip_nodes']}" if mu > 0
             else "frictionless")
    print(f"mu_f = {mu:4.2f}: F_abs = {row['F_abs']:8.1f}, contact nodes "
          f"{row['nodes_in_contact']} ({split}), |sigma - sigma(mu=0)| = "
          f"{row['sigma_vs_frictionless']:.1e}")

fig, ax = plt.subplots(figsize=(6.5, 4))
positive = [mu for mu in MUS if mu > 0]
ax.plot(positive, [by_mu[str(mu)]["stick_nodes"] for mu in positive], "o-", label="stick")
ax.plot(positive, [by_mu[str(mu)]["slip_nodes"] for mu in positive], "s-", label="slip")
ax.set(xlabel=r"friction coefficient $\mu_f$", ylabel=r"$\tilde h$-nodes in contact",
       title=f"Coulomb friction, level {LEVEL}: stick grows with $\\mu_f$")
ax.grid(alpha=0.3)
ax.legend()
lesson.save(fig, "stick_slip")

# %%
lesson.results({"sweep": sweep, "rho2s": RHO2S, "rho1s": RHO1S, "large_rho2": large,
                "by_mu": by_mu})
