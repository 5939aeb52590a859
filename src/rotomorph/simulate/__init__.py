"""Simulation drivers: filaments over a heating ramp, lattice designs, and the paper report."""
