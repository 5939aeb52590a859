"""Progress that works everywhere: a bar with counts and an ETA on a terminal, a line every few
seconds elsewhere (logs, notebooks, ``| tee``), the library's messages as its note, nothing
with --quiet; the commands' progress says what is counted, how far, and in °C."""

from __future__ import annotations

import fcntl
import io
import logging
import os
import pty
import re
import select
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest

import rotomorph._progress as progress_module
from rotomorph._progress import ProgressDisplay, format_duration, progress_display
from rotomorph.cli import EXIT_OK, main

ROOT = Path(__file__).resolve().parents[2]
FILAMENT = """schema_version = 1
name = "coil"
[[filaments]]
name = "w*=0.25"
speed = 0.25
rotation_number = 0.25
spacing = 0.5
segments = [{ kind = "line", length = 10.0 }]
"""


@pytest.fixture
def fast_lines(monkeypatch):
    """Progress lines every 50 ms (the first after 10 ms) instead of every 10 s."""
    monkeypatch.setattr(progress_module, "INTERVAL", 0.05)
    monkeypatch.setattr(progress_module, "FIRST_LINE", 0.01)


def test_format_duration():
    assert format_duration(0.4) == "0 s"
    assert format_duration(12.4) == "12 s"
    assert format_duration(185) == "3 min 05 s"
    assert format_duration(3720) == "1 h 02 min"


def test_lines_without_a_terminal_count_time_and_note():
    out = io.StringIO()
    with ProgressDisplay("simulate", 8, "steps", stream=out, interval=0.05, first=0.01) as shown:
        shown.set_task("filament 1 of 2 'coil'")
        shown.advance(3)
        shown.set_note("heating step 3 of 8 at 131.2 °C")
        time.sleep(0.2)
    lines = out.getvalue().splitlines()
    assert len(lines) >= 2, lines
    assert re.fullmatch(
        r"rotomorph: simulate: 3 of 8 steps \(38 %\), \d+ s elapsed, ETA \d+ s; "
        r"filament 1 of 2 'coil' · heating step 3 of 8 at 131\.2 °C",
        lines[0],
    ), lines[0]
    assert lines[-1].endswith("(finished)")
    assert "\r" not in out.getvalue()  # a log, not a redrawn bar


def test_a_short_command_writes_no_line():
    out = io.StringIO()
    with ProgressDisplay("simulate", 2, "steps", stream=out) as shown:
        shown.advance(2)
    assert out.getvalue() == ""


def test_bar_on_a_terminal_has_count_eta_and_note():
    out = io.StringIO()
    with ProgressDisplay("sweep", 10, "runs", stream=out, tty=True) as shown:
        shown.set_note("4 ok, 0 failed, 6 to go")
        shown.advance(4)
        shown._bar.refresh()
        text = out.getvalue()
    assert "sweep: 4 of 10 runs |" in text and "ETA" in text and "4 ok, 0 failed" in text


def test_eta_from_the_units_after_the_first_and_not_those_found_done():
    shown = ProgressDisplay("sweep", 12, "runs", enabled=False)
    shown.set_initial(6)  # a resumed sweep: 6 runs found finished
    assert shown.done == 6 and shown.eta() is None  # none computed yet
    time.sleep(0.3)  # the first run carries the pool's start-up
    shown.advance(1)
    assert shown.eta() is None
    time.sleep(0.1)
    shown.advance(2)  # 2 runs in 0.1 s after the first: 3 more take about 0.15 s
    eta = shown.eta()
    assert eta is not None and 0.1 <= eta <= 0.5, eta


def test_quiet_shows_nothing_and_verbose_echoes_messages():
    out = io.StringIO()
    log = logging.getLogger("rotomorph.progress")
    with progress_display("paper", 8, "computations", quiet=True, stream=out, tty=False):
        log.info("lattice dome", extra={"task": True})
    assert out.getvalue() == ""
    with progress_display("paper", 8, "computations", verbose=True, stream=out) as shown:
        log.info("lattice dome 5x5", extra={"task": True})
        log.info("ramp step %d of %d at %s", 3, 8, "131.2 °C")
        assert shown.note == "lattice dome 5x5 · ramp step 3 of 8 at 131.2 °C"
    assert out.getvalue().splitlines() == [
        "rotomorph: lattice dome 5x5",
        "rotomorph: ramp step 3 of 8 at 131.2 °C",
    ]


def test_filament_simulate_in_a_log_says_steps_and_degrees(tmp_path, capsys, fast_lines):
    design = tmp_path / "coil.toml"
    design.write_text(FILAMENT, encoding="utf-8")
    code = main(["simulate", str(design), "-o", str(tmp_path / "run"), "--steps", "4"])
    err = capsys.readouterr().err
    assert code == EXIT_OK, err
    lines = [ln for ln in err.splitlines() if ln.startswith("rotomorph: simulate: ")]
    assert lines, err
    # elapsed as format_duration writes it: "12 s", "1 min 05 s" (a loaded machine), "1 h 02 min"
    elapsed = r"(\d+ h \d+ min|(\d+ min )?\d+ s) elapsed"
    assert all(re.search(r"\d of 5 steps \(\d+ %\), " + elapsed, ln) for ln in lines), lines
    assert any("°C" in ln for ln in lines), lines
    assert lines[-1].startswith("rotomorph: simulate: 5 of 5 steps") and "(finished)" in lines[-1]


def test_lattice_simulate_counts_ramp_steps_in_degrees(tmp_path, capsys, fast_lines):
    text = (ROOT / "examples" / "designs" / "lattice_expanding.toml").read_text()
    design = tmp_path / "lattice.toml"
    design.write_text(text.replace("n = 5", "n = 2").replace("ghost_nodes = 10", "ghost_nodes = 2"))
    args = ["simulate", str(design), "-o", str(tmp_path / "run"), "--steps", "2", "--no-movie"]
    code = main(args)
    err = capsys.readouterr().err
    assert code == EXIT_OK, err
    lines = [ln for ln in err.splitlines() if ln.startswith("rotomorph: simulate: ")]
    # 2 steps and the path check's 4 sub-steps (path_check = 2 in the example), all counted
    assert lines and lines[-1].startswith("rotomorph: simulate: 6 of 6 ramp steps"), err
    assert any(re.search(r"ramp step \d of \d at [\d.]+ °C", ln) for ln in lines), lines
    assert "~0 s" not in err


def _pty_run(args: list[str], cwd: Path, timeout: float = 240.0) -> tuple[int, str]:
    """Run ``python -m rotomorph ARGS`` with stdout and stderr on a pseudo-terminal."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, 160, 0, 0))  # 160 columns
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.Popen(
        [sys.executable, "-m", "rotomorph", *args],
        stdin=slave,
        stdout=slave,
        stderr=slave,
        cwd=cwd,
        env=env,
        close_fds=True,
    )
    os.close(slave)
    chunks: list[bytes] = []
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([master], [], [], 0.5)
            if ready:
                try:
                    data = os.read(master, 65536)
                except OSError:  # the child closed the terminal
                    break
                if not data:
                    break
                chunks.append(data)
            elif proc.poll() is not None:
                break
    finally:
        os.close(master)
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    return proc.returncode, b"".join(chunks).decode("utf-8", "replace")


SWEEP = """schema_version = 1
name = "tiny"
outputs = ["end_to_end_ratio"]
[design]
schema_version = 1
[[design.filaments]]
speed = 1.0
rotation_number = 0.25
spacing = 1.0
segments = [{ kind = "line", length = 10.0 }]
[settings]
steps = 2
[[parameters]]
path = "filaments[0].speed"
values = [0.5, 1.0, 2.0]
"""


def test_sweep_shows_its_bar_on_a_terminal(tmp_path):
    """The sweep's bar (which once never showed) on a real pseudo-terminal."""
    sweep = tmp_path / "tiny.toml"
    sweep.write_text(SWEEP, encoding="utf-8")
    args = ["sweep", str(sweep), "-o", str(tmp_path / "out"), "--workers", "1"]
    code, text = _pty_run(args, tmp_path)
    assert code == 0, text
    assert re.search(r"sweep: \d of 3 runs \|", text), text
    assert "ok, 0 failed" in text and "to go" in text
    # the finished bar stays on the screen, above the summary line
    last = text.replace("\r\n", "\n").split("\n")[0].split("\r")[-1]
    assert re.match(
        r"sweep: 3 of 3 runs \|█+\| \d\d:\d\d, ETA 00:00, 3 ok, 0 failed, 0 to go", last
    ), text


def test_lattice_set_up_estimates_in_words():
    """The set-up line's estimates: never "~0 s" or "~0.0 GB" for a small lattice."""
    from rotomorph.simulate.design import _about_bytes, _about_seconds

    assert _about_seconds(0.3) == "under 1 s"
    assert _about_seconds(4.2) == "about 4 s"
    assert _about_seconds(300.0) == "about 5 min"
    assert _about_bytes(4.6e6) == "about 5 MB"
    assert _about_bytes(1e3) == "about 1 MB"
    assert _about_bytes(2.54e9) == "about 2.5 GB"


def test_paper_shows_its_plan_from_the_start(tmp_path, monkeypatch, capsys, fast_lines):
    """``paper`` reports its planned computations before the calibrations start, so its first
    lines say "0 of N computations" (before: a bare "0 computations" for the whole
    calibration)."""
    import rotomorph.simulate.report as report

    class Stop(Exception):
        pass

    def calibrations():  # stands for the calibrations: long enough for a line, then stop
        time.sleep(0.3)
        raise Stop

    monkeypatch.setattr(report, "validate_filaments", calibrations)
    calls = []
    with pytest.raises(Stop):
        report.paper_report(tmp_path, quick=True, progress=lambda *a: calls.append(a))
    assert calls == [(0, 5)]  # the calibrations, three filament sections, the authors' Fig. 4
    with pytest.raises(Stop):
        main(["paper", "-o", str(tmp_path / "out"), "--quick"])
    lines = [ln for ln in capsys.readouterr().err.splitlines() if "rotomorph: paper:" in ln]
    assert lines and all(re.match(r"rotomorph: paper: 0 of 5 computations", ln) for ln in lines)
