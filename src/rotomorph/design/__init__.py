"""Design layer: paths, print programs, networks and lattices (no mechanics)."""
