"""Solvers for the discrete problem (3.62): linear, Uzawa (3.38), projections, reference QP."""
