"""A sweep evaluator that logs every evaluation (run id, one line each) and is a bit slow.

Used by the kill-and-resume test through a subprocess: ``python _counting.py SWEEP DIR LOG``.
"""

from __future__ import annotations

import os
import sys
import time

from rotomorph.sweep import execute_run, load_sweep, run_sweep


def counting_run(spec):
    with open(os.environ["SWEEP_EVALUATION_LOG"], "a", encoding="utf-8") as fh:
        fh.write(spec.run_id + "\n")
    time.sleep(0.2)
    return execute_run(spec)


if __name__ == "__main__":
    sweep_path, folder, log = sys.argv[1:4]
    os.environ["SWEEP_EVALUATION_LOG"] = log
    run_sweep(load_sweep(sweep_path), folder, workers=2, evaluate=counting_run, max_pending=4)
