"""The set-up bench in a browser: `fretbuzz studio [INSTRUMENT]` (or `python3 -m fretbuzz.studio`)
serves a page at http://127.0.0.1:8035/ where the luthier sees the instrument's buzz map fill
in, hears each note and its contacts, tries what-ifs (truss rod, action, nut, saddle, one
fret, attack) against the map before, asks for the advice and exports a report for the
customer.

The page is a FastAPI application (app.py) served by uvicorn, drawn with Jinja2 templates;
the maps, what-ifs, comparisons, notes and advice are fretbuzz.Bench's (study.py keeps them
and runs them one at a time on a worker thread). It answers this computer only unless
started with --host (then every request needs the token printed in its address), serves
files from its study folder only, and works alone in that folder (its lock).
"""
from __future__ import annotations

import argparse
import os
import re
import socket
import sys
from typing import List, Optional, Sequence

__all__ = ["main", "serve", "server", "listen"]

DEFAULT_PORT = 8035


def _digits(text: str) -> bool:
    return re.fullmatch(r"[0-9]{1,9}", text) is not None  # ASCII digits ("٣".isdigit() is True)


def _port(text: str) -> int:
    if not _digits(text) or int(text) > 65535:
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


def _count(text: str) -> int:
    if not _digits(text):
        raise argparse.ArgumentTypeError(f"{text!r}: must be a whole number (ASCII digits)")
    return int(text)


def _real(text: str) -> float:
    # float() would take "٣", "1_0" and "nan" too.
    if not re.fullmatch(r"[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]{1,3})?", text):
        raise argparse.ArgumentTypeError(f"{text!r}: must be a number such as 48000 or 0.05 (ASCII digits)")
    return float(text)


def server(study, sock: socket.socket, host: Optional[str] = None, allow_hosts: Sequence[str] = (),
           token: Optional[str] = None):
    """A uvicorn server for the studio of a Study on a listening socket (run it with
    .run(sockets=[sock]); host: the --host it was started with, if any, allow_hosts the names
    other computers may use for this one, token the one its requests need with a host; the
    application is .config.app, its token .config.app.state.token)."""
    import uvicorn
    from .app import create_app
    app = create_app(study, port=sock.getsockname()[1], host=host, allow_hosts=allow_hosts, token=token)
    # proxy_headers off: the client's address is the socket's peer, never a header's claim.
    config = uvicorn.Config(app, log_level="warning", access_log=False, proxy_headers=False, lifespan="on")
    return uvicorn.Server(config)


def serve(study, sock: socket.socket, host: Optional[str] = None, allow_hosts: Sequence[str] = (),
          token: Optional[str] = None) -> None:
    """Serves the studio of a Study on a listening socket until SIGINT or SIGTERM."""
    try:
        server(study, sock, host, allow_hosts, token).run(sockets=[sock])
    finally:
        study.close()


def default_folder(name: str) -> str:
    """studio-NAME in the current folder: one component whatever the name (the instrument
    reader allows only plain names; this holds even if it did not)."""
    leaf = f"studio-{name}"
    if os.path.basename(leaf) != leaf or "\0" in leaf or leaf in (".", ".."):
        from ..setup_bench import InputError
        raise InputError(f"name = {name!r}: not a folder's name; give --study")
    return os.path.join(os.getcwd(), leaf)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="fretbuzz studio", description="The set-up bench in a browser.")
    parser.add_argument("instrument", nargs="?", default="jazz-bass",
                        help="a built-in instrument (jazz-bass, electric-guitar, bass-5, bass-neck) or an instrument file")
    parser.add_argument("--port", type=_port, default=DEFAULT_PORT, help=f"port (default {DEFAULT_PORT}; 0: any free port)")
    parser.add_argument("--host", help="serve other computers on this address, behind a token printed in the address "
                                       "(default: this computer only, 127.0.0.1)")
    parser.add_argument("--allow-host", action="append", default=[], metavar="NAME",
                        help="with --host: a name other computers use for this one in their address bar (repeatable)")
    parser.add_argument("--keep-maps", type=_count, metavar="N",
                        help="remove all but the newest N finished maps of the study folder before starting")
    parser.add_argument("--study", help="the study folder: the notes' sounds and the reports (default: studio-INSTRUMENT)")
    parser.add_argument("--strength", default="medium", help="the attacks of the first map (default: medium)")
    parser.add_argument("--ensemble", type=_count, help="plucks per note (default: the instrument's)")
    parser.add_argument("--fs", type=_real, help="sampling rate, Hz (default: the instrument's)")
    parser.add_argument("--duration", type=_real, help="seconds per note (default: the instrument's)")
    parser.add_argument("--jobs", type=_count, help="threads (default: every core)")
    parser.add_argument("--finger", action="store_true", help="stopped notes by the finger model (slow)")
    args = parser.parse_args(argv)
    try:
        import fastapi  # noqa: F401
        import jinja2  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError as e:
        print(f"fretbuzz studio: {e}: apt-get install python3-fastapi python3-uvicorn python3-jinja2", file=sys.stderr)
        return 1
    if args.allow_host and args.host is None:
        parser.error("--allow-host: give --host too (without it only this computer may connect)")
    from ..setup_bench import Bench, InputError
    from .study import Study, StudyBusy
    try:
        bench = Bench(args.instrument, strengths=args.strength, finger=args.finger, jobs=args.jobs,
                      ensemble=args.ensemble, fs=args.fs, duration=args.duration)
        study = Study(bench, args.study or default_folder(bench.instrument.name), strengths=args.strength,
                      start=False, keep_maps=args.keep_maps)
    except InputError as e:
        print(f"fretbuzz studio: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # StudyBusy names the studio that holds the folder
        print(f"fretbuzz studio: {'' if isinstance(e, StudyBusy) else 'cannot use the study folder: '}{e}",
              file=sys.stderr)
        return 1
    unfinished, old = study.pruned
    if unfinished or old:
        print(f"fretbuzz studio: removed {unfinished} unfinished and {old} old map(s) from {study.folder}", flush=True)
    host = args.host or "127.0.0.1"
    try:
        sock = listen(host, args.port)
    except OSError as e:
        print(f"fretbuzz studio: cannot listen on {host}:{args.port}: {e.strerror or e}"
              f"{' (try another --port, or 0 for any free one)' if e.errno == 98 else ''}", file=sys.stderr)
        return 1
    port = sock.getsockname()[1]
    shown = f"[{host.strip('[]')}]" if ":" in host else host
    import secrets
    token = secrets.token_urlsafe(24) if args.host is not None else None
    address = f"http://{shown}:{port}/" + (f"?token={token}" if token else "")
    print(f"fretbuzz studio: {address} ({bench.instrument.name}; study folder {study.folder}; Ctrl-C stops it)",
          flush=True)
    if args.host is not None:
        names = ", ".join(sorted({"127.0.0.1", "localhost", "::1", *args.allow_host} |
                                 ({host} if host not in ("0.0.0.0", "::") else set())))
        print(f"fretbuzz studio: warning: shared on the network: {host}:{port}"
              f"{' (every interface of this computer)' if host in ('0.0.0.0', '::') else ''}. Whoever has the address "
              f"above, token included, can queue maps and advice, and hear and download every sound and report of "
              f"{study.folder}; share it only with people you trust. The address is plain HTTP (readable on the "
              f"network). Browsers may reach it by an IP address or by {names} (--allow-host adds a name).",
              file=sys.stderr, flush=True)
    study.start()
    serve(study, sock, args.host, args.allow_host, token)
    return 0
