# %% [markdown]
# # Solutions to Tutorial 8: Your own scene
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

lesson = nd.Lesson("08_your_own_scene_solutions")
QUICK = lesson.quick
LEVELS = [1, 2, 3] if QUICK else [1, 2, 3, 4]
OUT = lesson.out


def stamp(load_factor: float = 1.0, gap: str = "0.001 + 0.05*x*x") -> nd.Scene:
    """The stamp of Tutorial 8, its load scaled by ``load_factor``, above the gap ``gap``."""
    labels = ["base", "right_clamp", "right_shoulder", "top", "left_shoulder", "left_clamp"]
    scene = nd.Scene(name="stamp", material=nd.scene.Material(E=200000.0, nu=0.3),
                     geometry=nd.scene.Geometry(kind="polygon", labels=labels, maxh=0.25, points=[
                         [-1.0, 0.0], [1.0, 0.0], [1.0, 0.25], [0.4, 1.0], [-0.4, 1.0],
                         [-1.0, 0.25]]),
                     boundary={"dirichlet": labels[1::4], "neumann": labels[2:5],
                               "contact": labels[:1]},
                     loads=nd.scene.Loads(traction=["0", f"{-1500 * load_factor}*(1 - x*x)"]),
                     contact=nd.scene.Contact(gap=gap))
    nd.validate(scene)
    return scene


# %% [markdown]
# ## Exercise 1: the load at first contact
#
# Before contact the discrete problem is linear in the load factor $s$ and in the gap
# $g$, and so is $\lambda_n$ (the discrete remaining gap):
# $\lambda_n(g, s) = \Lambda(g) - s\,U$ as long as no node touches. Two solves with a
# foundation far away ($g = 1$, never reached) give $\Lambda(1)$ (no load) and
# $U = \Lambda(1) - \lambda_n(1, 1)$. For the flat foundation $g_0$ the node $i$ closes
# when $g_0\,\Lambda(1)_i = s\,U_i$, so the first contact happens at
#
# $$
# s^* = \min_{i :\, U_i > 0} \frac{g_0\,\Lambda(1)_i}{U_i} .
# $$
#
# ($\Lambda(1)$ is not 1 near the ends of $\Gamma_C$: the coarse space vanishes there.)
# Check: $0.95\,s^*$ leaves a gap, $1.05\,s^*$ touches.

# %%
G0, LEVEL = 0.002, 2


unloaded = nd.solve(stamp(0.0, "1"), LEVEL).part("lam_n")
loaded = nd.solve(stamp(1.0, "1"), LEVEL).part("lam_n")
U = unloaded - loaded
closing = U > 0
s_star = float(np.min(G0 * unloaded[closing] / U[closing]))
near_contact = {factor: nd.solve(stamp(factor * s_star, str(G0)), LEVEL)
                for factor in (0.95, 1.05)}
touching = {factor: nd.result_record(solution)["contact"]["nodes_in_contact"]
            for factor, solution in near_contact.items()}
print(f"first contact at s* = {s_star:.4f}; nodes in contact at 0.95 s*: {touching[0.95]}, "
      f"at 1.05 s*: {touching[1.05]}")

# %%
fig, ax = plt.subplots(figsize=(7, 4))
for factor, solution in near_contact.items():
    traces = nd.contact_traces(solution)
    order = np.argsort(traces.node_xy[:, 0])
    ax.plot(traces.node_xy[order, 0], traces.lam_n[order], "o-", ms=3,
            label=f"load {factor} s* ({touching[factor]} nodes in contact)")
ax.axhline(0.0, color="k", lw=0.8)
ax.set_xlabel(r"$x_1$ on $\Gamma_C$ (the base)")
ax.set_ylabel(r"remaining gap $\lambda_n = g - u_n$")
ax.set_title(f"Exercise 1: first contact of the stamp at s* = {s_star:.3f} (g = {G0})")
ax.grid(True, alpha=0.3)
ax.legend()
lesson.save(fig, "first_contact")

# %% [markdown]
# ## Exercise 2: an arch on two feet
#
# A half annulus (radii 1 and 1.5) as a polygon with 8 segments per arc. Its feet (the
# two short bottom sides) rest on the foundation. If all the curved sides were loaded
# (Neumann), $\Gamma_N$ would touch $\Gamma_C$ at the feet, which the thesis' multipliers
# (zero at the ends of $\Gamma_C$, `contact.ends = "thesis"`) do not allow; so the lowest
# segment of each arc is clamped (an abutment). First two mistakes, then the fixed scene.

# %%
N = 8
angles = np.linspace(0.0, np.pi, N + 1)
outer = [[1.5 * np.cos(a), 1.5 * np.sin(a)] for a in angles]
inner = [[np.cos(a), np.sin(a)] for a in angles[::-1]]
points = [[1.0, 0.0]] + outer + inner[:-1]         # counter-clockwise, starts at right foot
labels = (["right_foot"] + ["outer_clamp"] + ["outer"] * (N - 2) + ["outer_clamp"]
          + ["left_foot"] + ["inner_clamp"] + ["inner"] * (N - 2) + ["inner_clamp"])
assert len(points) == len(labels)


def arch_toml(points, dirichlet, neumann, ends="consistent") -> str:
    coords = ", ".join(f"[{x:.6f}, {y:.6f}]" for x, y in points)
    return f"""
name = "arch"
[geometry]
kind = "polygon"
points = [{coords}]
labels = {labels}
maxh = 0.15
[boundary]
dirichlet = {dirichlet}
neumann = {neumann}
contact = ["right_foot", "left_foot"]
[loads]
traction = ["0", "-300"]
[contact]
gap = "0.0005"
ends = "{ends}"
"""


mistakes = {
    "everything loaded": arch_toml(points, ["outer_clamp"],
                                   ["inner_clamp", "outer", "inner"], ends="thesis"),
    "clockwise corners": arch_toml(points[::-1], ["outer_clamp", "inner_clamp"],
                                   ["outer", "inner"]),
}
arch_errors = {}
for what, text in mistakes.items():
    path = OUT / f"arch-{what.replace(' ', '-')}.toml"
    path.write_text(text)
    try:
        nd.load_scene(path)
    except nd.SceneError as err:
        arch_errors[what] = err.field
        print(f"{what}: {err}")
(OUT / "arch.toml").write_text(arch_toml(points, ["outer_clamp", "inner_clamp"],
                                         ["outer", "inner"]))
arch = nd.load_scene(OUT / "arch.toml")
arch_solution = nd.solve(arch, 2)
# λ_n is the remaining gap at the coarse nodes: a node touches where it is (numerically) 0
arch_gap = arch_solution.part("lam_n")
arch_contact = int(np.sum(arch_gap <= 1e-6 * 0.0005))
arch_mesh = arch_solution.problem.fes.mesh
lesson.save(nd.plot_geometry(arch, mesh=arch_mesh,
                             title="Exercise 2: the arch, its boundary parts and mesh (level 2)"),
            "arch_geometry")
lesson.save(nd.plot_von_mises(arch_mesh, nd.fields(arch_solution).sigma, arch.material.nu,
                              "Exercise 2: von Mises stress in the arch on its two feet"),
            "arch_von_mises")
print(f"fixed arch: converged {arch_solution.converged}, remaining gap at the foot nodes "
      f"{np.array2string(arch_gap, precision=6)}: {arch_contact} of {len(arch_gap)} touch")

# %% [markdown]
# ## Exercise 3: convergence under refinement
#
# $\|\sigma\|_X$ converges; the differences between consecutive levels shrink roughly like
# $h$ (first order, Theorem 3.35 for smooth solutions; the kinks at the corners and the
# contact zone limit the rate). The share of $\Gamma_C$ nodes in contact settles as the
# contact zone is resolved.

# %%
scene = stamp()
rows = []
for level in LEVELS:
    record = nd.result_record(nd.solve(scene, level))
    rows.append((level, record["norms"]["sigma_X"],
                 record["contact"]["nodes_in_contact"] / record["dofs"]["C"]))
differences = np.abs(np.diff([r[1] for r in rows]))
orders = np.log2(differences[:-1] / differences[1:]) if len(differences) > 1 else []
for (level, norm, share) in rows:
    print(f"level {level}: |sigma|_X = {norm:.5e}, share of nodes in contact {share:.2f}")
print(f"observed orders of |sigma|_X differences: {np.round(orders, 2)}")

# %%
lesson.results({"s_star": s_star, "touching": {str(k): v for k, v in touching.items()},
                "arch_errors": arch_errors, "arch_contact": arch_contact,
                "refinement": rows})
