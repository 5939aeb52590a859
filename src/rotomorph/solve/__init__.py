"""Solvers: a generic modified-Newton minimiser and static equilibrium of rod networks."""
