"""The ``rotomorph serve`` command: a local web application (``rotomorph.app``).

Bound to 127.0.0.1 by default (only this computer reaches it); ``--host 0.0.0.0`` serves the
local network, which has no login: do that only on a network you trust. The browser opens the
page unless ``--no-open``. Stops on Ctrl-C, ending every worker process.
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from rotomorph.errors import InvalidParameterError

__all__ = ["DESCRIPTION", "add_arguments", "command", "default_examples"]

#: ``rotomorph serve --help``'s description.
DESCRIPTION = (
    "The designer in the browser: a local web application to edit a design, see its "
    "prediction, simulate it, preview and download its G-code, and design inversely. Listens "
    "on 127.0.0.1 unless --host says otherwise (there is no login: serve another address only "
    "on a network you trust); opens the browser unless --no-open; Ctrl-C stops it. Needs "
    'pip install "rotomorph[app]".'
)


def default_examples() -> Path | None:
    """The repository's ``examples/`` folder when rotomorph runs from a source checkout."""
    here = Path(__file__).resolve().parents[3] / "examples"
    return here if (here / "designs").is_dir() else None


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``rotomorph serve``."""
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    p.add_argument("--port", type=int, default=8050, help="port (default 8050; 0: any free one)")
    p.add_argument("--no-open", dest="open", action="store_false", help="do not open a browser")
    p.add_argument(
        "--examples",
        metavar="DIR",
        help="folder with designs/ and machines/ to offer (default: the repository's examples/)",
    )
    p.add_argument(
        "--max-jobs",
        type=int,
        default=None,
        help="simulations and inverse designs running at once over all sessions (default: cores)",
    )
    p.add_argument(
        "--no-prewarm",
        dest="prewarm",
        action="store_false",
        help="start each session's worker cold: no warm-up heating while the person designs "
        "(less CPU; a lattice's first simulated step then comes later)",
    )


def command(args: argparse.Namespace) -> int:
    """Run the server until interrupted (exit 0)."""
    if not 0 <= args.port <= 65535:
        raise InvalidParameterError("--port", f"must be 0..65535; got {args.port}")
    if args.max_jobs is not None and args.max_jobs < 1:
        raise InvalidParameterError("--max-jobs", f"must be >= 1; got {args.max_jobs}")
    examples = Path(args.examples) if args.examples else default_examples()
    if examples is not None and not examples.is_dir():
        raise InvalidParameterError("--examples", f"{args.examples}: no such folder")
    try:
        from rotomorph.app.server import create_app
    except ImportError as err:
        raise InvalidParameterError(
            "serve", f"the app needs its extra: pip install 'rotomorph[app]' ({err})"
        ) from None
    from rotomorph.app.jobs import Sessions
    from rotomorph.app.server import LOCAL_HOSTS

    local = args.host in LOCAL_HOSTS
    app, sessions = create_app(
        examples=examples,
        sessions=Sessions(max_jobs=args.max_jobs, prewarm=args.prewarm),
        allowed_hosts=LOCAL_HOSTS if local else None,
    )
    import socket

    from werkzeug.serving import make_server

    try:  # bound here: werkzeug would print its own words and exit on a taken port
        family = socket.AF_INET6 if ":" in args.host else socket.AF_INET
        listener = socket.create_server((args.host, args.port), family=family)
    except (OSError, ValueError, OverflowError) as err:  # port taken, not this computer's
        sessions.close()
        reason = getattr(err, "strerror", None) or str(err)
        raise InvalidParameterError(
            "--host/--port", f"cannot listen on {args.host}:{args.port}: {reason}; pick another"
        ) from None
    server = make_server(args.host, args.port, app.server, threaded=True, fd=listener.fileno())
    shown = {"0.0.0.0": "127.0.0.1", "::": "::1"}.get(args.host, args.host)
    url = f"http://{f'[{shown}]' if ':' in shown else shown}:{listener.getsockname()[1]}/"
    logging.getLogger("werkzeug").setLevel(logging.WARNING)
    sys.stderr.write(f"rotomorph: serving the designer at {url} (Ctrl-C stops it)\n")
    sys.stderr.flush()
    if not local:
        sys.stderr.write(
            f"rotomorph: warning: listening on {args.host}: anyone who reaches it can use it "
            "(there is no login)\n"
        )
    if args.open:
        import webbrowser

        webbrowser.open(url)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
        sessions.close()
    return 0
