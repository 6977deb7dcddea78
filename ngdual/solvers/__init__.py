"""Solvers for the discrete problem (3.62): linear, Uzawa (3.38), nested Uzawa (3.41), the
active-set solver on Gamma_C (fast), projections, and the reference QP."""
