"""Single filaments against the paper
==================================

Single filaments vs the paper's measurements, out of sample: one JSON object per line.

Calibration is a joint weighted fit (with weak, stated priors) of E_a/E_p at the actuation
temperature, the threshold strain law ε∥ = −gain (S(v) − S0) and the passive strain to three
groups of filament measurements: Janus curvature vs speed (Fig. 2D), pure-LCE and composite
L/L0 vs ω* (Fig. 2F/G). Both modulus-ratio branches (E_a/E_p ≥ 1 and ≤ 1; bilayer curvature
is symmetric under m ↔ 1/m) are fitted and the choice is recorded.

Every row's ``predicted`` comes from the model calibrated WITHOUT that row's group
(leave-one-group-out); the sinusoids are never fitted. ``predicted_sd`` is the calibration's
uncertainty propagated to the prediction; ``z`` uses the combined spread
√(spread² + predicted_sd²); ``calibration`` is true only for inputs (order parameters, passive
free length) and ``converged`` compares two resolutions (1 % tolerance).

Run: ``python examples/filaments_vs_paper.py [--figure PATH]``: rows on stdout, the score line
on stderr, and with ``--figure`` every prediction against its measurement (PNG). The same rows,
plus lattices, are in ``rotomorph paper``'s summary.json.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from rotomorph.plot.figure import save_figure
from rotomorph.plot.report import plot_parity
from rotomorph.simulate.validation import summarise, summary_line, validate_filaments


def rows() -> list[dict[str, Any]]:
    """One row per measured filament quantity (see the module docstring)."""
    return validate_filaments().rows


def main(argv: list[str] | None = None) -> int:
    """Print one JSON object per measured quantity to stdout and the score line to stderr."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--figure", type=Path, help="write predicted against measured (PNG)")
    args = parser.parse_args(argv)
    out = rows()
    for row in out:
        sys.stdout.write(json.dumps(row) + "\n")
    score = summary_line(summarise(out))
    sys.stderr.write(score + "\n")
    if args.figure is not None:
        title = f"Single filaments, each group predicted without its own data\n{score}"
        save_figure(plot_parity(out, title=title), args.figure)
    return 0


if __name__ == "__main__":
    main()  # always 0; not SystemExit, which would end a documentation build running it
