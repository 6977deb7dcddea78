"""Fig. 3.10: the domain of Example 3.46, its boundary parts, the load and the rigid foundations.

Left: Omega = [-4, 4] x [-1, 1] with Gamma_D (clamped ends), Gamma_N (top, loaded by t_0 on
[-2, 2]) and Gamma_C (bottom), the level-1 mesh, and the foundation x_2 = -1 - g(x_1) for a
constant gap (red, g = 0.01 drawn 20x enlarged) and the gap (3.125) (blue). Right: the four
gap functions of the shipped scenes. No solve: data/fig_3_10_geometry.csv samples t_0 and g.
"""

import numpy as np

from ngdual import plot
from ngdual.expr import Expression
from ngdual.mesh import mesh_arrays, thesis_mesh
from ngdual.scene import load_scene
from ngdual.studies.figures import script_main

THESIS = "Fig. 3.10"
STUDIES = ()
GAPS = {"g = 0.01 (thesis-3.46-coulomb)": "thesis-3.46-coulomb",
        "g = 0 (thesis-3.46-coulomb-gap0)": "thesis-3.46-coulomb-gap0",
        "g = |x_1| (thesis-3.46-coulomb-gap-abs)": "thesis-3.46-coulomb-gap-abs",
        "g of (3.125) (thesis-3.46-coulomb-gap-3125)": "thesis-3.46-coulomb-gap-3125"}


def run(ctx):
    # COMPUTE: the load t_0 and the gap functions on a fine sample of x_1
    x = np.linspace(-4, 4, 801)
    scene = load_scene("thesis-3.46-coulomb")
    load = Expression(scene.loads.traction[1]).numpy(x, np.ones_like(x))
    gaps = {label: Expression(load_scene(name).contact.gap).numpy(x, -np.ones_like(x))
            for label, name in GAPS.items()}
    mesh = thesis_mesh(1)
    points, triangles = mesh_arrays(mesh)
    # WRITE
    rows = [{"x1": xi, "t0_2": ti, **{label: g[i] for label, g in gaps.items()}}
            for i, (xi, ti) in enumerate(zip(x, load))]
    data = ctx.write_csv("fig_3_10_geometry.csv", rows,
                         "Example 3.46: traction t_0,2 on Gamma_N and gap functions g on Gamma_C")
    # PLOT
    fig = plot.plot_domain(points, triangles, x, load,
                           [(x, -1 - 20 * gaps[list(GAPS)[0]], "constant gap g = 0.01 (x20)",
                             {"color": "red"}),
                            (x, -1 - gaps[list(GAPS)[3]], "gap (3.125)",
                             {"color": "blue", "ls": "--"})],
                           [(x, g, label, {}) for label, g in gaps.items()],
                           "Example 3.46: geometry, boundary parts and rigid foundations",
                           units=scene.units)
    figs = plot.save_figure(fig, ctx.figure_stem("fig_3_10_geometry"))
    ctx.entry(THESIS, "Geometry, boundary parts and rigid foundations", [*figs, data],
              numbers={"min t_0,2 (at x_1 = 0)": float(load.min()),
                       "gap (3.125) at x_1 = -4, 0, 0.4, 4": [
                           float(Expression(load_scene(GAPS[list(GAPS)[3]]).contact.gap)
                                 .numpy(np.array([v]), np.array([-1.0]))[0])
                           for v in (-4.0, 0.0, 0.4, 4.0)]},
              thesis_says="Gamma_D = {-4, 4} x [-1, 1], Gamma_N = [-4, 4] x {1}, Gamma_C = "
                          "[-4, 4] x {-1}; t_0 = (0, -800(1 - x^2/2 + x^4/16)) on [-2, 2]; "
                          "E = 200 000, nu = 0.25.")


if __name__ == "__main__":
    script_main(__file__)
