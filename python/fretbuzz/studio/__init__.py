"""The set-up bench in a browser: `fretbuzz studio [INSTRUMENT]` (or `python3 -m fretbuzz.studio`)
serves a page at http://127.0.0.1:8035/ where the luthier sees the instrument's buzz map fill
in, hears each note and its contacts, tries what-ifs (truss rod, action, nut, saddle, one
fret, attack) against the map before, asks for the advice and exports a report for the
customer.

The page is a FastAPI application (app.py) served by uvicorn, drawn with Jinja2 templates;
the maps, what-ifs, comparisons, notes and advice are fretbuzz.Bench's (study.py keeps them
and runs them one at a time on a worker thread). It answers this computer only unless
started with --host, and serves files from its study folder only.
"""
from __future__ import annotations

import argparse
import os
import socket
import sys
from typing import List, Optional

__all__ = ["main", "serve", "server", "listen"]

DEFAULT_PORT = 8035


def _port(text: str) -> int:
    if not text.isdigit() or int(text) > 65535:
        raise argparse.ArgumentTypeError(f"{text}: must be a whole number in [0, 65535] (0: any free port)")
    return int(text)


def listen(host: str, port: int) -> socket.socket:
    """A socket listening on host:port (port 0: a free one), IPv6 for an address with colons."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host.strip("[]"), port))
        sock.listen(64)
    except OSError:
        sock.close()
        raise
    sock.set_inheritable(True)
    return sock


def server(study, sock: socket.socket, host: Optional[str] = None):
    """A uvicorn server for the studio of a Study on a listening socket (run it with
    .run(sockets=[sock]); host: the --host it was started with, if any)."""
    import uvicorn
    from .app import create_app
    app = create_app(study, port=sock.getsockname()[1], host=host)
    # proxy_headers off: the client's address is the socket's peer, never a header's claim.
    config = uvicorn.Config(app, log_level="warning", access_log=False, proxy_headers=False, lifespan="on")
    return uvicorn.Server(config)


def serve(study, sock: socket.socket, host: Optional[str] = None) -> None:
    """Serves the studio of a Study on a listening socket until SIGINT or SIGTERM."""
    try:
        server(study, sock, host).run(sockets=[sock])
    finally:
        study.close()


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="fretbuzz studio", description="The set-up bench in a browser.")
    parser.add_argument("instrument", nargs="?", default="jazz-bass",
                        help="a built-in instrument (jazz-bass, electric-guitar, bass-5, bass-neck) or an instrument file")
    parser.add_argument("--port", type=_port, default=DEFAULT_PORT, help=f"port (default {DEFAULT_PORT}; 0: any free port)")
    parser.add_argument("--host", help="serve other computers on this address (default: this computer only, 127.0.0.1)")
    parser.add_argument("--study", help="the study folder: the notes' sounds and the reports (default: studio-INSTRUMENT)")
    parser.add_argument("--strength", default="medium", help="the attacks of the first map (default: medium)")
    parser.add_argument("--ensemble", type=int, help="plucks per note (default: the instrument's)")
    parser.add_argument("--fs", type=float, help="sampling rate, Hz (default: the instrument's)")
    parser.add_argument("--duration", type=float, help="seconds per note (default: the instrument's)")
    parser.add_argument("--jobs", type=int, help="threads (default: every core)")
    parser.add_argument("--finger", action="store_true", help="stopped notes by the finger model (slow)")
    args = parser.parse_args(argv)
    try:
        import fastapi  # noqa: F401
        import jinja2  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError as e:
        print(f"fretbuzz studio: {e}: apt-get install python3-fastapi python3-uvicorn python3-jinja2", file=sys.stderr)
        return 1
    from ..setup_bench import Bench, InputError
    from .study import Study
    try:
        bench = Bench(args.instrument, strengths=args.strength, finger=args.finger, jobs=args.jobs,
                      ensemble=args.ensemble, fs=args.fs, duration=args.duration)
        folder = args.study or f"studio-{bench.instrument.name}"
        study = Study(bench, folder, strengths=args.strength, start=False)
    except InputError as e:
        print(f"fretbuzz studio: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"fretbuzz studio: cannot use the study folder: {e}", file=sys.stderr)
        return 1
    host = args.host or "127.0.0.1"
    try:
        sock = listen(host, args.port)
    except OSError as e:
        print(f"fretbuzz studio: cannot listen on {host}:{args.port}: {e.strerror or e}"
              f"{' (try another --port, or 0 for any free one)' if e.errno == 98 else ''}", file=sys.stderr)
        return 1
    port = sock.getsockname()[1]
    shown = f"[{host.strip('[]')}]" if ":" in host else host
    print(f"fretbuzz studio: http://{shown}:{port}/ ({bench.instrument.name}; study folder {study.folder}; Ctrl-C stops it)",
          flush=True)
    from .app import is_loopback
    if args.host is not None and not is_loopback(host.strip("[]")) and host != "localhost":
        print(f"fretbuzz studio: serving other computers on {host}: anyone who reaches port {port} may use it", flush=True)
    study.start()
    serve(study, sock, args.host)
    return 0
