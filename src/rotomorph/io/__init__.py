"""Input/output: toolpaths, G-code, results (HDF5, JSON), ParaView files; written atomically."""
