"""The ``rotomorph predict`` command: parser arguments and the command (logic lives here).

``rotomorph predict DESIGN.toml`` prints one line per filament (curvature, twist, radius,
pitch, L/L0 with their calibration band, the morphology and the handedness) or, for a lattice,
its independent-edge estimate; ``rotomorph predict --for curvature=0.4`` prints the print
settings that give a wanted shape. ``--json`` prints one JSON object instead. Settings outside
the calibrated range are said on the line (``EXTRAPOLATED: …``) and in the JSON
(``extrapolated``). Nothing is written to disk.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

from rotomorph.errors import InvalidParameterError

__all__ = ["add_arguments", "command"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``rotomorph predict``."""
    p.add_argument("design", nargs="?", metavar="DESIGN.toml")
    p.add_argument(
        "--for",
        dest="wanted",
        action="append",
        metavar="NAME=VALUE",
        help="the print settings giving a shape instead: curvature (1/mm), twist (1/mm, > 0 "
        "right-handed), radius, pitch (mm), L/L0; speed= or rotation_number= fixes a setting; "
        "repeat or join with commas for two",
    )
    p.add_argument(
        "--active-fraction",
        type=float,
        default=0.5,
        help="with --for: 0.5 (Janus composite, default) or 1 (pure LCE)",
    )
    p.add_argument(
        "--temperature",
        type=float,
        default=175.0,
        help="heating temperature (°C; default 175, the calibration's)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _emit(record: dict[str, Any], lines: list[str], as_json: bool) -> None:
    if as_json:
        sys.stdout.write(json.dumps(record, indent=2, allow_nan=False) + "\n")
        return
    for line in lines:
        sys.stdout.write(line + "\n")


def command(args: argparse.Namespace) -> int:
    """Run ``rotomorph predict`` (exit 0; bad input raises InvalidParameterError: exit 2)."""
    if args.wanted:
        if args.design is not None:
            raise InvalidParameterError("predict", "give DESIGN.toml or --for NAME=VALUE, not both")
        if args.temperature != 175.0:
            raise InvalidParameterError(
                "--temperature", "--for answers at the calibration temperature 175 °C only"
            )
        from rotomorph.prediction.settings import parse_request, settings_for

        answer = settings_for(parse_request(args.wanted), active_fraction=args.active_fraction)
        _emit(answer.record(), [answer.line()], args.json)
        return 0
    if args.design is None:
        raise InvalidParameterError("predict", "give DESIGN.toml (or --for NAME=VALUE)")
    if not math.isfinite(args.temperature) or not -50.0 <= args.temperature <= 300.0:
        raise InvalidParameterError(
            "--temperature", f"must be a temperature in -50..300 °C; got {args.temperature:g}"
        )
    path = Path(args.design)
    if not path.is_file():
        raise InvalidParameterError(
            "DESIGN", f"{args.design}: no such file" if not path.exists() else "is a folder"
        )
    from rotomorph.io.designfile import load_design
    from rotomorph.prediction.design import predict_design

    prediction = predict_design(load_design(path), temperature=args.temperature)
    lines = [f"{args.design}: '{prediction.name}' at {args.temperature:g} °C (± calibration band)"]
    _emit(prediction.record(), lines + prediction.lines(), args.json)
    return 0
