"""A sweep owner for the owner-death test: ``python _owner.py SWEEP DIR PIDS``.

Every run writes its worker's pid to the folder PIDS and then sleeps for a minute, so the test
can kill this process while its workers are busy.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from rotomorph.sweep import execute_run, load_sweep, run_sweep


def sleeping_run(spec):
    if spec.error is not None:  # known-invalid points are recorded by the owner itself
        return execute_run(spec)
    (Path(os.environ["SWEEP_WORKER_PIDS"]) / str(os.getpid())).write_text(spec.run_id)
    time.sleep(60.0)
    return execute_run(spec)


if __name__ == "__main__":
    sweep_path, folder, pids = sys.argv[1:4]
    os.environ["SWEEP_WORKER_PIDS"] = pids
    print("owner", os.getpid(), flush=True)
    run_sweep(load_sweep(sweep_path), folder, workers=2, evaluate=sleeping_run)
