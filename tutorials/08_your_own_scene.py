# %% [markdown]
# # Tutorial 8: Your own scene
#
# **Run time** on a 2-core laptop: about 4 s; about 5 s with `NGDUAL_QUICK=1`
# (`ngdual tutorials run 08 --quick`).
#
# **The idea in words.** A scene file describes a problem in words and numbers: the
# outline of the body and the names of its sides, which sides are held, loaded or may
# touch the foundation, the material and the loads. ngdual checks it before anything is
# meshed and names every mistake. This tutorial writes a new scene, previews its geometry,
# solves it on a few meshes and reads the results in Python; the command line does the same
# with the same file.
#
# **Problem.** A new geometry, set up without writing any finite element code: an
# elastic stamp (a hexagon) clamped at its two short vertical sides, loaded from
# above, resting on a *curved* rigid foundation with gap $g(x) = 0.001 + 0.05\,x^2$: the
# frictionless Signorini problem (3.68) on a domain that is not a rectangle.
#
# **Discretisation.** Whatever the scene calls for: netgen meshes the polygon, PEERS
# (3.61) discretises $(\sigma, u, \eta)$, the multipliers live on the coarse boundary
# meshes, and Algorithm 3.38 solves the contact problem (frictionless, so no $\nu$ and no
# outer friction loop).
#
# **What you will learn.**
# 1. The TOML scene format: geometry, boundary roles, material, loads, contact, solver.
# 2. What validation catches, and what the error messages look like: each names the
#    offending field, so you know which line of the file to fix.
# 3. Solving on several levels (uniform refinement) and reading the result record, the one
#    the command line `ngdual solve` writes to `result.json`.
#
# **References.** M. Andres, *Dual-dual formulations for frictional contact problems in
# mechanics*, PhD thesis, Leibniz Universität Hannover, 2011:
# eqs. (3.1), (3.61), (3.68), Algorithm 3.38; the scene
# schema in `ngdual/scene/tables.py`; the shipped scenes (`ngdual scenes`).

# %% [markdown]
# ## Parameters

# %%
import numpy as np

import ngdual as nd

lesson = nd.Lesson("08_your_own_scene")           # figures, scene files, results.json go here
QUICK = lesson.quick


def mesh_size(mesh) -> float:
    """The largest triangle diameter h (its longest edge), as in Table 3.1."""
    points, triangles = nd.mesh_arrays(mesh)
    corners = points[triangles]
    return max(float(np.linalg.norm(corners[:, i] - corners[:, i - 1], axis=1).max())
               for i in range(3))
LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]
OUT = lesson.out

# %% [markdown]
# ## 1. Writing the scene
#
# A scene is a TOML file. The polygon is listed **counter-clockwise**; side $i$ runs from
# point $i$ to point $i+1$ and gets label $i$. Every label must get exactly one role:
# `dirichlet` ($u = u_D$, here 0), `neumann` (traction $t_0$) or `contact`. Loads, the
# gap and friction bounds are formulas in `x` and `y`. The thesis assumes that $\Gamma_N$
# and $\Gamma_C$ do not touch (its multipliers vanish at the ends of $\Gamma_C$,
# `contact.ends = "thesis"`), which is why the clamped sides separate the loaded top from
# the base here. With the default `contact.ends = "consistent"` they may touch: the
# multipliers are free there.

# %%
SCENE = """
name = "stamp-on-curved-foundation"
description = "Hexagonal stamp, clamped short sides, loaded from above, curved foundation"

[geometry]
kind = "polygon"
points = [[-1.0, 0.0], [1.0, 0.0], [1.0, 0.25], [0.4, 1.0], [-0.4, 1.0], [-1.0, 0.25]]
labels = ["base", "right_clamp", "right_shoulder", "top", "left_shoulder", "left_clamp"]
maxh = 0.25

[boundary]
dirichlet = ["left_clamp", "right_clamp"]
neumann = ["right_shoulder", "top", "left_shoulder"]
contact = ["base"]

[material]
E = 200000.0
nu = 0.3

[loads]
traction = ["0", "-1500*(1 - x*x)"]      # downwards, largest in the middle

[contact]
gap = "0.001 + 0.05*x*x"                 # a convex foundation below the base

[solver]
metric = "h12"
"""
scene_file = OUT / "stamp.toml"
scene_file.write_text(SCENE)
scene = nd.load_scene(scene_file)
lesson.save(nd.plot_geometry(scene, level=LEVELS[0]), "geometry")
print(f"loaded {scene.name!r}: {len(scene.geometry.points)} corners, "
      f"contact on {scene.labels('contact')}, friction law {scene.friction.law!r}")

# %% [markdown]
# ## 2. Common mistakes, and the errors they give
#
# `load_scene` validates everything before any mesh is built, and raises one
# `SceneError` whose `field` names the entry to fix. The overrides below are the same
# `section.key=value` strings that `ngdual solve --set` takes; the last one changes the
# file itself.

# %%
clockwise = SCENE.replace(
    "[[-1.0, 0.0], [1.0, 0.0], [1.0, 0.25], [0.4, 1.0], [-0.4, 1.0], [-1.0, 0.25]]",
    "[[-1.0, 0.25], [-0.4, 1.0], [0.4, 1.0], [1.0, 0.25], [1.0, 0.0], [-1.0, 0.0]]")
(OUT / "clockwise.toml").write_text(clockwise)
MISTAKES = [
    ("a typo in a boundary label", scene_file, ["boundary.contact=['bsae']"]),
    ("a side without a condition", scene_file, ["boundary.dirichlet=['left_clamp']"]),
    ("the loaded part touches the contact part, with the thesis' ends", scene_file,
     ["contact.ends='thesis'", "boundary.dirichlet=['left_clamp']",
      "boundary.neumann=['right_clamp', 'right_shoulder', 'top', 'left_shoulder']"]),
    ("an incompressible material", scene_file, ["material.nu=0.5"]),
    ("a foundation that cuts into the body", scene_file, ["contact.gap='0.05*x'"]),
    ("a misspelt key", scene_file, ["material.youngs_modulus=2e5"]),
    ("corners listed clockwise", OUT / "clockwise.toml", []),
]
caught = []
for what, path, overrides in MISTAKES:
    try:
        nd.load_scene(path, overrides)
    except nd.SceneError as err:
        caught.append(err.field)
        print(f"{what}:\n    field {err.field!r}\n    {err}")
    else:
        print(f"{what}: not caught!")

# %% [markdown]
# The command line validates the same way. Typed in a terminal in the folder of
# `stamp.toml`,
#
# ```bash
# ngdual solve stamp.toml --set material.nu=0.5 --out never-written
# ```
#
# prints the message of the fourth mistake on one line and exits with status 2 (bad
# input) without writing anything.

# %% [markdown]
# ## 3. Solving and refining
#
# `nd.solve(scene, level)` meshes (level $k$ = $k - 1$ uniform refinements of the netgen
# mesh), assembles only what the scene needs and runs the matching algorithm, here
# Algorithm 3.38. The record of `post.result_record` is what `ngdual solve` writes to
# `result.json`.

# %%
levels, records = [], []
for level in LEVELS:
    solution = nd.solve(scene, level)
    record = nd.result_record(solution)
    records.append(record)
    levels.append({"level": level, "h": mesh_size(solution.problem.fes.mesh),
                   "dofs": record["dofs"], "converged": record["converged"],
                   "iterations": record["iterations"]["outer"],
                   "sigma_X": record["norms"]["sigma_X"], "lam_n": record["norms"]["lam_n"],
                   "nodes_in_contact": record["contact"]["nodes_in_contact"],
                   "sigma_n_positive": record["residuals"]["sigma_n_positive"]})
print(f"{'level':>5} {'h':>6} {'dim X':>6} {'dim C':>5} {'its':>4} {'in contact':>10} "
      f"{'|sigma|_X':>10}")
for row in levels:
    print(f"{row['level']:5d} {row['h']:6.3f} {row['dofs']['X']:6d} {row['dofs']['C']:5d} "
          f"{row['iterations']:4d} {row['nodes_in_contact']:10d} {row['sigma_X']:10.4e}")

# %% [markdown]
# Pictures of the finest level: the von Mises stress (the colour scale clipped at a
# percentile stated on the colour bar, because of the corners, see below; in a notebook
# also NGSolve's interactive webgui) and the traces on $\Gamma_C$.

# %%
mesh = solution.problem.fes.mesh
sigma_h = nd.fields(solution).sigma
lesson.save(nd.plot_von_mises(mesh, sigma_h, scene.material.nu,
                              f"von Mises stress, {scene.name}, level {LEVELS[-1]}"),
            "von_mises")
lesson.save(nd.plot_contact_traces(nd.contact_traces(solution),
                                   f"Traces on Γ_C, {scene.name}, level {LEVELS[-1]}"),
            "contact_traces")
lesson.draw(nd.post.von_mises(sigma_h, scene.material.nu), mesh, "von_mises")

# %% [markdown]
# How the body moves: `nd.plot_deformed` draws the mesh displaced by $u_h$, magnified so
# that the largest displacement is a few percent of the body's size (the title states the
# factor; the foundation is not magnified, so the magnified body crosses it where it
# touches).

# %%
lesson.save(nd.plot_deformed(solution), "deformed")

# %% [markdown]
# Two things stand out, and both are mathematics rather than bugs:
#
# * The stress concentrates at the corners where a clamped side meets the base. Mixed
#   boundary conditions meeting at a corner make $\sigma$ singular there (like
#   $r^{\alpha-1}$ with $\alpha < 1$, $r$ the distance to the corner), so these peaks grow
#   under uniform refinement. Adaptive refinement (Chapter 4) is the remedy.
# * Near the ends of $\Gamma_C$, $\sigma_n^h$ takes both signs. The multipliers vanish at
#   $\partial\Gamma_C$ (the space $C_{\tilde h}$ of (3.61)), so the sign condition
#   $\sigma_n \le 0$ is imposed only weakly, tested with coarse hat functions
#   ($(3.62)_6$) whose weight goes to zero at the ends of $\Gamma_C$.

# %% [markdown]
# The same from the command line (the scene file is an ordinary path):
#
# ```bash
# ngdual solve stamp.toml --level 1 --out cli
# ```
#
# solves level 1, prints a summary table and writes `cli/result.json` (and its plots):
# the record `nd.result_record` returned above, section by section:

# %%
first = records[0]
print("the sections of result.json:", ", ".join(first))
print(f"level {first['level']}: converged {first['converged']}, "
      f"nodes in contact {first['contact']['nodes_in_contact']}")

# %%
lesson.results({"caught": caught,
                "expected_fields": ["boundary.contact", "boundary", "contact.ends", "material.nu",
                                    "contact.gap", "material.youngs_modulus", "geometry.points"],
                "record_sections": list(first), "levels": levels})

# %% [markdown]
# ## Exercises
# Solutions: `tutorials/solutions/08_your_own_scene_solutions.py`.
#
# 1. **First contact.** Make the foundation flat ($g = 0.002$) and find the load factor
#    $s$ (traction $s\,t_0$) at which the stamp first touches it. Hint: before contact the
#    problem is linear, so one solve without a contact boundary suffices.
# 2. **An arch.** Write a scene for an arch (a half annulus, approximated by a polygon)
#    whose two feet rest on the foundation. Which sides must be Dirichlet so that
#    validation accepts it? Trigger, read and fix two validation errors on the way.
# 3. **Refinement.** Solve on levels 1-4 and estimate the convergence order of
#    $\|\sigma\|_X$ and of the number of nodes in contact (relative to the number of
#    $\Gamma_C$ nodes).
