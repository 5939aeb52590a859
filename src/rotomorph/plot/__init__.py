"""Figures (matplotlib, Agg) and animations (GIF through Pillow); files written atomically."""
