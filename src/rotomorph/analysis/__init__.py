"""Analysis layer: lengths, areas, curvatures and shape descriptors of solved configurations."""
