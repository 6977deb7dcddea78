# %% [markdown]
# # Solutions to Tutorial 3: Tresca and Coulomb friction, the nested Uzawa algorithm
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import numpy as np

from ngdual import peers, post
from ngdual.forms import assemble
from ngdual.friction import build_friction_forms
from ngdual.mesh import build_mesh
from ngdual.scene import load_scene
from ngdual.solvers.nested import nested_uzawa
from ngdual.solvers.result import ConvergenceError
from ngdual.solvers.settings import NestedUzawaSettings, UzawaSettings
from ngdual.solvers.uzawa import uzawa
from ngdual.studies.tutorials import output_dir, quick_mode, save_results

QUICK = quick_mode()
LEVEL = 3                                             # the first level with a stick zone
RHO1S = [1.0] if QUICK else [0.5, 1.0, 1.5]
RHO2S = [0.5, 1.0, 1.5] if QUICK else [0.25, 0.5, 1.0, 1.5]
LARGE_RHO2S = [2.5, 8.0]
GAP_ABS_LEVEL = 3 if QUICK else 4
MUS = [0.0, 0.1, 0.5, 1.0] if QUICK else [0.0, 0.1, 0.25, 0.5, 1.0]
OUT = output_dir("03_friction_solutions")
coulomb = load_scene("thesis-3.46-coulomb")
problem = assemble(coulomb, build_mesh(coulomb.geometry, LEVEL))


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
# With ν outside (Algorithm 3.41) the number of *outer* steps depends on ρ₂ only, like
# the contraction factor 1 − cρ₂ of a projected gradient method: halving ρ₂ about doubles
# it. Each outer step runs a whole inner Uzawa loop, whose length depends on ρ₁. With the
# loops exchanged (Remark 3.43) the outer count depends on ρ₁ and the cheap ν loop runs
# inside; counted in inner iterations (= solves with the condensed Γ_C response) the
# exchanged order is usually cheaper here.
#
# ρ₂ is measured relative to the computed bound 2/λ_max(H) of the *unconstrained* ν
# iteration (Theorem 3.42 gives a cruder bound of the same kind). Beyond it the
# iteration may still converge: on slip edges |ν| = 1 is enforced by the projection,
# which is a contraction whatever the step, so only stick edges can be excited. Where
# there is a stick zone, a step far beyond the bound stalls, and `nested_uzawa` says so.

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

# %% [markdown]
# ## Exercise 2: ĥ = h̃ when (3.73) holds
#
# With g = |x₁| the body touches only around x₁ = 0, far from the ends of Γ_C: 𝓕 = 0
# near ∂Γ_C, the hats next to the ends of A_C pin the checkerboard mode, and the
# inf-sup condition (3.74) holds with ĥ = h̃ (Lemma 3.31). Both choices converge, and λ_n,
# λ_t agree up to the discretisation difference of ν (Figs. 3.26-3.27). ν itself is a
# different function on the two ĥ meshes; it is printed on A_C = supp 𝓕 only (elsewhere
# 𝓕 is zero up to round-off and ν does not enter (3.62)).

# %%
gap_abs = {}
for factor in (1, 2):
    scene = load_scene("thesis-3.46-coulomb-gap-abs", [f"contact.hhat_factor={factor}"])
    gap_abs[factor] = nested_uzawa(assemble(scene, build_mesh(scene.geometry, GAP_ABS_LEVEL)),
                                   NestedUzawaSettings.from_scene(scene, eps2=1e-8))
a, b = gap_abs[1], gap_abs[2]
scale = max(np.linalg.norm(b.part("lam_n")), np.linalg.norm(b.part("lam_t")))
gap_abs_difference = {name: float(np.linalg.norm(a.part(name) - b.part(name)) / scale)
                      for name in ("lam_n", "lam_t")}
for factor, solution in gap_abs.items():
    forms = build_friction_forms(solution.problem)
    F_hat = forms.per_hat_edge(solution.friction_bound)
    on_a_c = (F_hat > 1e-6 * F_hat.max())[forms.edge_of]
    print(f"h^ = {factor} h~: {solution.iterations}, converged {solution.converged}; "
          f"nu on the fine edges of A_C: {np.round(solution.nu[forms.edge_of][on_a_c], 2)}")
print(f"difference of the multipliers (relative): {gap_abs_difference}")

# %% [markdown]
# ## Exercise 3: the friction coefficient
#
# With μ_f = 0 the friction bound vanishes, ν plays no role and the nested algorithm
# solves the frictionless problem: σ agrees with Algorithm 3.38 to the solver tolerance.
# Growing μ_f adds friction forces, so F_abs grows, and the tangential stress can be
# carried without slip on a growing part of the contact zone: the stick zone grows.

# %%
frictionless = load_scene("thesis-3.46-frictionless")
reference = uzawa(assemble(frictionless, build_mesh(frictionless.geometry, LEVEL)),
                  UzawaSettings.from_scene(frictionless, eps=1e-10))
by_mu = {}
for mu in MUS:
    solution = nested_uzawa(problem, NestedUzawaSettings.from_scene(coulomb, mu_f=mu, eps1=1e-10,
                                                                    eps2=1e-9))
    summary = post.contact_summary(solution)
    by_mu[str(mu)] = {"converged": solution.converged, "F_abs": summary["F_abs"],
                      "nodes_in_contact": summary["nodes_in_contact"],
                      "stick_nodes": summary["stick_nodes"], "slip_nodes": summary["slip_nodes"],
                      "sigma_vs_frictionless": float(
                          np.linalg.norm(solution.part(*peers.STRESS)
                                         - reference.part(*peers.STRESS))
                          / np.linalg.norm(reference.part(*peers.STRESS)))}
    row = by_mu[str(mu)]
    # with F = 0 there are no h^ edges in A_C: the stick/slip split is meaningless
    split = (f"stick {row['stick_nodes']}, slip {row['slip_nodes']}" if mu > 0
             else "frictionless")
    print(f"mu_f = {mu:4.2f}: F_abs = {row['F_abs']:8.1f}, contact nodes "
          f"{row['nodes_in_contact']} ({split}), |sigma - sigma(mu=0)| = "
          f"{row['sigma_vs_frictionless']:.1e}")

# %%
save_results("03_friction_solutions",
             {"sweep": sweep, "rho2s": RHO2S, "rho1s": RHO1S, "large_rho2": large,
              "gap_abs_converged": [s.converged for s in gap_abs.values()],
              "gap_abs_difference": gap_abs_difference, "by_mu": by_mu})
