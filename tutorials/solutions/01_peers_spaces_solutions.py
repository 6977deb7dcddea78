# %% [markdown]
# # Solutions to Tutorial 1: The PEERS spaces, their unknowns and the discrete inf-sup condition
#
# Each exercise is one section; all run in seconds with `NGDUAL_QUICK=1`.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ngdual as nd

infsup = nd.verification.infsup                  # Gram matrices and singular values of B
lesson = nd.Lesson("01_peers_spaces_solutions")
QUICK = lesson.quick
LEVELS = [1, 2] if QUICK else [1, 2, 3, 4]

# %% [markdown]
# ## Exercise 1: the inf-sup constant in the $L^2$ norm
#
# Brezzi's theory needs $b$ to be *continuous* and inf-sup stable in the same pair of
# norms, both uniformly in $h$. We compute the smallest and the largest singular value
# of $B$ in both norms. The smallest barely changes (it is decided by smooth modes, for
# which $\|\operatorname{div}\tau\| \sim \|\tau\|$). The largest is bounded in
# $H(\operatorname{div})$ but grows like $1/h$ in $L^2$: a rough $\tau$ with
# $\|\tau\| = 1$ has $\|\operatorname{div}\tau\| \sim 1/h$. In the $L^2$ norm $b$ is not
# uniformly continuous, so no $h$-independent error estimate can come out of it; in
# $\|\cdot\|_X$ both constants are $h$-independent, which is what Lemma 3.28 and
# Theorem 3.34 use.

# %%
clamped = nd.load_scene("thesis-3.46-frictionless",
                        ["boundary.dirichlet=['left', 'right', 'bottom', 'top']",
                         "boundary.neumann=[]", "boundary.contact=[]"])

singular = {"hdiv": [], "l2": []}
for level in LEVELS:
    problem = nd.assemble(clamped, nd.build_mesh(clamped.geometry, level))
    s, m = problem.sigma, problem.mult
    B = problem.block(s, m)
    for key, with_div in (("hdiv", True), ("l2", False)):
        G = infsup.gram_matrix(problem, with_div)
        X, Y = G[s][:, s], G[m][:, m]
        singular[key].append((float(infsup.smallest_singular_values(X, B, Y, k=1)[0]),
                              infsup.largest_singular_value(X, B, Y)))
    print(f"level {level}: (smallest, largest) in H(div) "
          f"({singular['hdiv'][-1][0]:.3f}, {singular['hdiv'][-1][1]:.3f}),  in L2 "
          f"({singular['l2'][-1][0]:.3f}, {singular['l2'][-1][1]:.3f})")
growth = {key: values[-1][1] / values[0][1] for key, values in singular.items()}
print(f"largest singular value grew by {growth['l2']:.2f} (L2) and {growth['hdiv']:.2f} "
      f"(H(div)) over {len(LEVELS) - 1} halvings of h")

fig, ax = plt.subplots(figsize=(6.5, 4.5))
hs = [np.sqrt(2.0) * 2.0 ** (1 - level) for level in LEVELS]
for key, marker, name in (("hdiv", "o", "H(div)"), ("l2", "s", "L²")):
    ax.loglog(hs, [v[0] for v in singular[key]], marker + "-", label=f"smallest, {name}")
    ax.loglog(hs, [v[1] for v in singular[key]], marker + "--", label=f"largest, {name}")
ax.set_xlabel("mesh size h")
ax.set_ylabel("singular value of B")
ax.set_title("Extreme singular values of b + s in two norms on X_h")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
lesson.save(fig, "singular_values")

# %% [markdown]
# ## Exercise 2: counting with Euler's formula
#
# Level $k$ of Example 3.46 has $n = 2^{k-1}$, an $8n \times 2n$ grid of squares, so
# $V = (8n + 1)(2n + 1)$, $T = 2 \cdot 16n^2$ and, by Euler, $E = V + T - 1$. Hence
#
# $$
# \dim X_h = 2(E + T), \qquad \dim M_h = 2T = 64n^2, \qquad \dim S_h = V .
# $$

# %%
TABLE_3_1 = {1: (180, 64, 27), 2: (680, 256, 85), 3: (2640, 1024, 297),
             4: (10400, 4096, 1105), 5: (41280, 16384, 4257), 6: (164480, 65536, 16705),
             7: (656640, 262144, 66177), 8: (2624000, 1048576, 263425)}


def formula(level: int) -> tuple[int, int, int]:
    n = 2 ** (level - 1)
    vertices, triangles = (8 * n + 1) * (2 * n + 1), 32 * n * n
    edges = vertices + triangles - 1
    return 2 * (edges + triangles), 2 * triangles, vertices


assert all(formula(k) == TABLE_3_1[k] for k in TABLE_3_1)
thesis = nd.load_scene("thesis-3.46-frictionless")
for level in LEVELS:
    dofs = nd.assemble(thesis, nd.build_mesh(thesis.geometry, level)).spaces.dofs()
    assert (dofs["X"], dofs["M"], dofs["S"]) == formula(level)
print("Euler's formula reproduces all eight rows of Table 3.1")

# %%
lesson.results({"singular_values": singular, "growth_of_largest": growth})
