"""``--scheduler`` pointed at something that is not a Dask scheduler (a web server, a silent
port, a Dask worker, nothing at all) fails within the handshake timeout with one line, before
any output folder exists; a real scheduler passes."""

from __future__ import annotations

import socket
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import pytest

import rotomorph.sweep.executors as executors
from rotomorph.cli import EXIT_USAGE, main
from rotomorph.errors import InvalidParameterError
from rotomorph.sweep.executors import probe_scheduler

distributed = pytest.importorskip("distributed")

SWEEP = (
    'schema_version = 1\noutputs = ["end_to_end_ratio"]\n'
    "[design]\nschema_version = 1\n[[design.filaments]]\nspacing = 0.5\n"
    'segments = [{kind = "line", length = 8.0}]\n[settings]\nmethod = "closed_form"\n'
    '[[parameters]]\npath = "filaments[0].speed"\nvalues = [1.0, 2.0]\n'
)
TIMEOUT = 2.0


class _Quiet(BaseHTTPRequestHandler):
    def do_GET(self):
        self.send_response(200)
        self.end_headers()
        self.wfile.write(b"<html>dashboard</html>")

    def log_message(self, *args):
        pass


@pytest.fixture
def http_port():
    server = ThreadingHTTPServer(("127.0.0.1", 0), _Quiet)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield server.server_address[1]
    server.shutdown()
    server.server_close()


@pytest.fixture
def silent_port():
    """A port that accepts connections and never says a word."""
    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    sock.listen(8)
    held = []
    stop = threading.Event()

    def accept():
        sock.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(sock.accept()[0])
            except OSError:
                continue

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    yield sock.getsockname()[1]
    stop.set()
    thread.join()
    for conn in held:
        conn.close()
    sock.close()


@pytest.fixture
def short_handshake(monkeypatch):
    monkeypatch.setattr(executors, "HANDSHAKE_TIMEOUT_S", TIMEOUT)


@pytest.mark.parametrize("kind", ["http", "silent"])
def test_cli_fails_within_the_timeout(request, kind, short_handshake, tmp_path, capsys):
    port = request.getfixturevalue(f"{kind}_port")
    path = tmp_path / "s.toml"
    path.write_text(SWEEP)
    out = tmp_path / "out"
    t0 = time.monotonic()
    code = main(["sweep", str(path), "-o", str(out), "--scheduler", f"tcp://127.0.0.1:{port}"])
    elapsed = time.monotonic() - t0
    assert code == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("rotomorph: error: --scheduler: ")
    assert "Traceback" not in err and not out.exists()
    assert elapsed < 3 * TIMEOUT + 5, f"took {elapsed:.1f} s"


def test_nothing_listening_fails_at_once():
    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    sock.close()
    t0 = time.monotonic()
    with pytest.raises(InvalidParameterError, match="nothing listens there"):
        probe_scheduler(f"tcp://127.0.0.1:{port}", timeout=TIMEOUT)
    assert time.monotonic() - t0 < TIMEOUT


def test_a_scheduler_passes_and_a_worker_is_named():
    with distributed.LocalCluster(
        n_workers=1, processes=False, protocol="tcp", dashboard_address=None
    ) as cluster:
        probe_scheduler(cluster.scheduler_address, timeout=TIMEOUT)
        worker = next(iter(cluster.scheduler.workers))
        with pytest.raises(InvalidParameterError, match="answers as a Dask Worker"):
            probe_scheduler(worker, timeout=TIMEOUT)
