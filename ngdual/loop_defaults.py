"""The defaults of the adaptive loop, in one place: :func:`ngdual.adapt` takes them and the
command line states them in ``ngdual adapt --help`` (a light module: the parser imports it
without NGSolve)."""

# The thesis' marking (Section 4.2, Tables 4.1-4.4): Doerfler with theta = 0.5.
MARKING, THETA = "dorfler", 0.5
# Doerfler's theta of a tolerance-driven run. With growth g per step the loop's time to a
# target is about g / ln g times one solve of the mesh the target needs (all steps, and the
# overshoot of the last), least at g = e. theta = 0.9 grows the unknowns faster than 0.8 on
# every problem and order measured (mean growth per step 1.08-2.75 against 1.07-2.36; the
# goals whose estimate sits on a few triangles grow by 1.1-1.3x at either;
# docs/theory/estimator.md, "A goal and a tolerance").
THETA_TOL = 0.9
# The least factor by which a step multiplies the triangles, and with them the unknowns
# (ngdual.afem.refinement.refine_graded: the marked triangles refined, then the triangles at
# the peaks of their estimate, again until the mesh has grown by it). The thesis' runs refine
# the marked triangles alone (GROWTH = 1: their meshes are the thesis'). A tolerance run's
# estimate may sit at a few points, where Doerfler's set grows the unknowns by 1.04-1.3x a
# step and every step pays its assembly, estimate and refinement again; a tolerance run
# grows by GROWTH_TOL at least (docs/theory/estimator.md, "Steps that pay"). MAX_GROWTH is
# the bound of the setting, the growth of refining every triangle.
GROWTH, GROWTH_TOL, MAX_GROWTH = 1.0, 1.5, 4.0
# The number of solves: the thesis' runs take 5; a tolerance-driven run stops by its
# tolerance (or the memory budget), and STEPS_TOL only bounds a tolerance it cannot reach.
STEPS, STEPS_TOL = 5, 30
# The initial level of a tolerance-driven run: the coarsest. On a finer start mesh the first
# steps refine a band around the singularities or Gamma_C inside a mesh already fine
# elsewhere and grow the unknowns by 1.01-1.2x (hertz-cylinder --goal pressure --tol 0.01:
# 4.6 s from level 1, 12.5 s from level 2, 11.7 s from its level 3; docs/theory/estimator.md).
LEVEL_TOL = 1
