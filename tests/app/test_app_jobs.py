"""Background jobs: a session's worker process streams each converged step and writes the run
with the CLI's own functions; one job per session and a cap over all sessions; cancel ends the
job at once and the session gets a fresh worker; a worker warms up unless told not to, and a
job submitted during its warm-up does not wait for it.

These tests measure no first step's latency, so their sessions' workers start cold (the
warm-up's own test excepted): the first job loads the kernels it needs itself."""

from __future__ import annotations

import time
import uuid

import numpy as np
import pytest
import tomli_w

from rotomorph.app.jobs import BusyError, Job, Sessions, Worker
from rotomorph.app.worker import WARM_STAGES
from rotomorph.cli import main
from rotomorph.io.results import read_results

DESIGN = {
    "schema_version": 1,
    "name": "two lines",
    "filaments": [
        {
            "rotation_number": 0.25,
            "spacing": 1.0,
            "start": [10.0, 10.0 + 5.0 * i, 0.0],
            "segments": [{"kind": "line", "length": 8.0}],
        }
        for i in range(2)
    ],
}
SLOW = {  # a long lattice ramp: still running when it is cancelled
    "schema_version": 1,
    "lattice": {"n": 5, "spacing": 5.0, "amplitude": 1.25, "pattern": "dome", "ghost_nodes": 10},
}


def _wait(sessions: Sessions, sid: str, until, timeout: float = 180.0) -> Job:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        job = sessions.job(sid)
        if job is not None and until(job):
            return job
        time.sleep(0.1)
    raise AssertionError(f"timed out: {sessions.job(sid)}")


@pytest.fixture(scope="module")
def sessions():
    s = Sessions(max_jobs=1, prewarm=False)
    yield s
    s.close()


def test_a_run_streams_every_step_and_writes_the_clis_files(sessions, tmp_path):
    sid = uuid.uuid4().hex
    sessions.submit(
        sid, Job("simulate", steps=2), {"kind": "simulate", "design": DESIGN, "steps": 2}
    )
    with pytest.raises(BusyError, match="a job is running in this session"):
        sessions.submit(
            sid, Job("simulate", steps=2), {"kind": "simulate", "design": DESIGN, "steps": 2}
        )
    with pytest.raises(BusyError, match=r"1 job\(s\) are running"):
        sessions.submit(
            uuid.uuid4().hex,
            Job("simulate", steps=2),
            {"kind": "simulate", "design": DESIGN, "steps": 2},
        )
    job = _wait(sessions, sid, lambda j: not j.running)
    assert job.state == "done", job.error
    steps = job.step_events()
    assert [(e["unit"], e["step"]) for e in steps] == [(u, k) for u in (0, 1) for k in range(3)]
    assert job.topology is not None and len(job.topology["units"]) == 2
    assert job.first_step_s is not None and job.first_step_s > 0
    # the same run from the command line: the same states
    design = tmp_path / "d.toml"
    design.write_text(tomli_w.dumps(DESIGN), encoding="utf-8")
    assert (
        main(["simulate", str(design), "-o", str(tmp_path / "cli"), "--steps", "2", "--no-movie"])
        == 0
    )
    ours = read_results(f"{job.result['folder']}/results.h5")
    cli = read_results(tmp_path / "cli" / "results.h5")
    np.testing.assert_allclose(ours.positions, cli.positions, rtol=0, atol=1e-12)
    assert sorted(p.name for p in (tmp_path / "cli").iterdir()) == sorted(
        p.name for p in __import__("pathlib").Path(job.result["folder"]).iterdir()
    )
    # what the page draws while a run goes on: the run viewer's figure of the steps so far
    from rotomorph.app import views

    partial = views.partial_results(job)
    assert partial.positions.shape == (6, *ours.positions.shape[1:])
    np.testing.assert_allclose(partial.positions[-1], ours.positions[-1], atol=1e-5)
    first = steps[2]["positions"]  # filament 0 at its last step, in frame 2
    np.testing.assert_allclose(partial.positions[2][: len(first)], first, atol=0)
    figure = views.stream_figure(job)
    assert figure is not None and len(figure.frames) == 6
    assert "(step 5/5)" in figure.layout.title.text
    # drawn as it streams: the first steps whole, then a Patch of the new steps only, which
    # makes the same frames as the whole figure (the page's figure with it applied)
    from dataclasses import replace

    store: dict = {}
    events = job.events
    early = replace(job, events=[e for e in events if e["kind"] != "step"] + steps[:2])
    whole, shown = views.stream_update(early, None, store)
    assert shown == 2 and len(whole.frames) == 2
    assert "(step 1/5)" in whole.layout.title.text  # the run's last frame when it ends
    later = replace(early, events=early.events + steps[2:])
    later.started = early.started
    store["stream"]["key"] = (id(later), later.started)
    assert views.stream_update(later, 1, store)[1] == 6  # the page lacks one: drawn whole
    store["stream"].update(shown=2)
    patch, shown = views.stream_update(later, 2, store)
    assert shown == 6 and type(patch).__name__ == "Patch"
    fig = whole.to_plotly_json()
    fig["frames"] = [f.to_plotly_json() for f in whole.frames]
    for op in patch.to_plotly_json()["operations"]:
        *where, last = op["location"]
        node = fig
        for key in where:
            node = node[key]
        if op["operation"] == "Extend":
            node[last].extend(op["params"]["value"])
        else:
            assert op["operation"] == "Assign"
            node[last] = op["params"]["value"]
    assert [f["name"] for f in fig["frames"]] == [str(k) for k in range(6)]
    assert [s["args"][0] for s in fig["layout"]["sliders"][0]["steps"]] == [
        [str(k)] for k in range(6)
    ]
    assert "(step 5/5)" in fig["layout"]["title"]["text"]
    assert "(step 4/5)" in fig["frames"][4]["layout"]["title"]["text"]
    assert views.stream_update(later, 6, store) is None  # nothing new
    streamed = [e["positions"] for e in steps if e["unit"] == 1]
    np.testing.assert_allclose(streamed[-1], ours.positions[-1][-len(streamed[-1]) :], atol=1e-5)


def test_cancel_ends_a_running_job_and_the_next_one_runs(sessions):
    sid = uuid.uuid4().hex
    sessions.submit(
        sid, Job("simulate", steps=60), {"kind": "simulate", "design": SLOW, "steps": 60}
    )
    job = _wait(sessions, sid, lambda j: len(j.step_events()) >= 2 or not j.running)
    assert job.running, job.error
    started = time.monotonic()
    sessions.cancel(sid)
    assert time.monotonic() - started < 6.0
    assert job.state == "cancelled" and not job.running
    sessions.submit(
        sid, Job("simulate", steps=1), {"kind": "simulate", "design": DESIGN, "steps": 1}
    )
    assert _wait(sessions, sid, lambda j: not j.running).state == "done"


def test_a_failed_job_reports_the_clis_line(sessions):
    sid = uuid.uuid4().hex
    bad = {**DESIGN, "filaments": [{**DESIGN["filaments"][0], "speed": -1.0}]}
    sessions.submit(sid, Job("simulate", steps=1), {"kind": "simulate", "design": bad, "steps": 1})
    job = _wait(sessions, sid, lambda j: not j.running)
    assert job.state == "failed"
    assert job.error.startswith("filaments[0].speed: must be >= ")


def _ready(worker: Worker, timeout: float = 180.0) -> None:
    end = time.monotonic() + timeout
    while not worker.ready:
        assert time.monotonic() < end, "the worker never reported ready"
        worker.poll()
        time.sleep(0.1)


def test_a_worker_warms_up_and_a_job_submitted_meanwhile_does_not_wait():
    worker = Worker(prewarm=True)
    try:
        _ready(worker)  # idle: every warm-up design heated
        assert worker.warmed == [name for name, _ in WARM_STAGES] == ["filament", "lattice"]
        worker.cancel()  # a fresh process, warming up again; a job at once
        assert not worker.ready and worker.warmed == []
        job = Job("simulate", steps=1)
        worker.submit(job, {"kind": "simulate", "design": DESIGN, "steps": 1})
        end = time.monotonic() + 180.0
        while worker.poll() is job and job.running:
            assert time.monotonic() < end, "the job never ended"
            time.sleep(0.1)
        assert job.state == "done", job.error
        assert worker.ready and "lattice" not in worker.warmed  # the job stopped the warm-up
    finally:
        worker.close()
    cold = Worker(prewarm=False)
    try:
        _ready(cold)
        assert cold.warmed == []
    finally:
        cold.close()
