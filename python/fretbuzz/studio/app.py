"""The studio's web application (FastAPI): the page, its JSON and HTML fragments, the study
folder's files, and the guard that keeps it to this computer (or, shared with --host, to
requests with its token).

Routes:
  GET  /                 the page
  GET  /api/state        the queue, the map under way (progress), the set-up now (JSON)
  POST /api/what-if      queue the map of the page's controls (JSON); 422 names each bad control
  POST /api/advice       queue the advice for the newest finished map ({"tolerate": ...} as --tolerate)
  POST /api/dress        queue the fret dress for the newest finished map (the same)
  POST /api/heard        one note of the player's report: {string, fret, strength, heard: buzz/clean/""}
  POST /api/calibrate    queue the calibration of that report, then the calibrated map and advice
  POST /api/export       write the customer's report into the study folder
  GET  /fragment/maps    the map and the one before it, with the changes marked (HTML)
  GET  /fragment/neck    the side views of the neck for a map (HTML)
  GET  /fragment/advice  the advice (HTML)
  GET  /fragment/dress   the fret dress (HTML)
  GET  /fragment/player  the player's report and its calibration (HTML)
  GET  /fragment/note    one note: its sound and its contacts over time (HTML)
  GET  /study/PATH       a file of the study folder (a note's WAV, a report)
  GET  /static/...       the page's script and style sheet
"""
from __future__ import annotations

import base64
import errno
import hmac
import ipaddress
import json
import os
import re
import secrets
from typing import Dict, Iterable, Optional

from fastapi import FastAPI, Request
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse, Response
from fastapi.staticfiles import StaticFiles
from jinja2 import Environment, FileSystemLoader, select_autoescape

from .. import _core
from ..setup_bench import Bench, InputError
from . import present
from .study import QUEUE_LIMIT, SERVED_SUFFIXES, FieldErrors, Study, StudyPathError

HERE = os.path.dirname(os.path.abspath(__file__))
LOOPBACK_NAMES = {"127.0.0.1", "localhost", "::1"}
MAX_BODY_BYTES = 16 * 1024
# Where the export writes its bytes: a test puts a full disk here.
write_bytes = os.write


class BodyTooLarge(Exception):
    """A request body past MAX_BODY_BYTES, however it was sent."""


class NoSpace(OSError):
    """The study folder's disk is full (or its quota spent)."""


def templates() -> Environment:
    """The studio's Jinja2 templates (the report includes the style sheet from static/)."""
    env = Environment(loader=FileSystemLoader([os.path.join(HERE, "templates"), os.path.join(HERE, "static")]),
                      autoescape=select_autoescape(["html", "j2"]), trim_blocks=True, lstrip_blocks=True)
    env.filters["mm"] = lambda v, digits=2: "" if v is None else f"{v:.{digits}f}"
    return env


def is_loopback(address: Optional[str]) -> bool:
    try:
        return address is not None and ipaddress.ip_address(address.split("%")[0]).is_loopback
    except ValueError:
        return False


def whole(text: str) -> bool:
    """ASCII digits only (str.isdigit takes "٣" and "³" too)."""
    return re.fullmatch(r"[0-9]+", text) is not None


def host_name(header: str) -> tuple:
    """A Host header's name and port ("[::1]:8035" -> ("::1", 8035)); port None when absent, -1
    when not a number."""
    header = header.strip().lower()
    if header.startswith("["):
        name, _, rest = header[1:].partition("]")
        port = rest[1:] if rest.startswith(":") else ""
    else:
        name, _, port = header.partition(":")
    return name, (int(port) if whole(port) and len(port) <= 5 else None if not port else -1)


def is_address(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
        return True
    except ValueError:
        return False


def refusal(status: int, message: str, close: bool = False) -> JSONResponse:
    # close: the client may still be sending a body this answer will not read.
    return JSONResponse({"error": message}, status_code=status, headers={"Connection": "close"} if close else None)


class Guard:
    """Who may talk to the studio.

    Without a host (the default): only loopback clients, naming the server by a loopback name
    and its own port in Host (so that a web page whose name was made to resolve to 127.0.0.1,
    DNS rebinding, is refused), and changes only from the page itself (Origin, a JSON body: a
    cross-site form cannot send one without asking).

    With a host (exposed): any client, but each request carries the token (the printed
    address's ?token=..., kept by the browser as a cookie), and Host still names this server:
    a loopback name, the host's own name, a name in allow_hosts, or an address (a page that
    reaches the port by an address is that address's own page, not a rebinding one)."""

    def __init__(self, port: int, host: Optional[str] = None, allow_hosts: Iterable[str] = (),
                 token: Optional[str] = None):
        self.port = port
        self.open = host is not None
        self.token = (token or secrets.token_urlsafe(24)) if self.open else None
        self.cookie = f"fretbuzz_studio_{port}"  # cookies ignore ports: one per studio
        wildcard = host in ("0.0.0.0", "::", "")
        self.names = LOOPBACK_NAMES | {n.strip("[]").lower() for n in allow_hosts}
        if host and not wildcard:
            self.names.add(host.strip("[]").lower())

    def ours(self, name: str, port: Optional[int]) -> bool:
        """Whether host:port names this server (no port: 80)."""
        return (80 if port is None else port) == self.port and (name in self.names or (self.open and is_address(name)))

    def has_token(self, request: Request) -> Optional[str]:
        """Where the request carries the token: "cookie", or "query" (the response then sets the
        cookie); None when it carries none, or another."""
        for given, how in ((request.cookies.get(self.cookie), "cookie"), (request.query_params.get("token"), "query")):
            if given is not None and hmac.compare_digest(given.encode(), self.token.encode()):
                return how
        return None

    def refuse(self, request: Request) -> Optional[Response]:
        client = request.client.host if request.client else None
        if not self.open and not is_loopback(client):
            return refusal(403, f"refused: the studio answers this computer only (loopback), not {client}; "
                                "start it with --host to serve other computers", close=True)
        host = request.headers.get("host", "")
        if not self.ours(*host_name(host)):
            return refusal(400, f"refused: Host {host!r} is not this studio (http://127.0.0.1:{self.port}/"
                                f"{'; --allow-host adds a name' if self.open else ''})", close=True)
        if self.open and not self.has_token(request):
            return refusal(401, "refused: this studio is shared on the network and needs its token: open the "
                                "address it printed (…/?token=…)", close=True)
        # A body is read only up to MAX_BODY_BYTES (_json); one without a length is not read at all.
        if "transfer-encoding" in request.headers:
            return refusal(411, f"refused: a request body is sent with its Content-Length (at most "
                                f"{MAX_BODY_BYTES} bytes)", close=True)
        length = request.headers.get("content-length")
        if length is not None and (not whole(length) or int(length) > MAX_BODY_BYTES):
            return refusal(413, f"refused: a request body over {MAX_BODY_BYTES} bytes", close=True)
        if request.method not in ("GET", "HEAD"):
            origin = request.headers.get("origin")
            if origin is not None and not (origin.startswith("http://") and self.ours(*host_name(origin[7:]))):
                return refusal(403, f"refused: a change from {origin} (only the studio's own page may change it)")
            if request.headers.get("content-type", "").split(";")[0].strip() != "application/json":
                return refusal(415, "refused: changes are sent as JSON")
        return None


async def _json(request: Request):
    body = bytearray()
    async for chunk in request.stream():  # never more than the limit in memory, whatever the headers said
        body += chunk
        if len(body) > MAX_BODY_BYTES:
            raise BodyTooLarge()
    try:
        return json.loads(bytes(body) or b"{}")
    except RecursionError:
        raise FieldErrors({"form": "the request nests too deep to be the page's controls"}) from None
    except ValueError:
        raise FieldErrors({"form": "the request is not JSON"}) from None


def _jobs_state(study: Study) -> dict:
    def job(j) -> dict:
        return {"id": j.id, "kind": j.kind, "label": j.label, "superseded_by": j.superseded_by}
    with study.lock:
        running = study.running
        state = {"running": None, "pending": [job(j) for j in study.pending],
                 "superseded": [job(j) for j in study.superseded], "limit": QUEUE_LIMIT}
        if running is not None:
            state["running"] = {**job(running), "done": len(running.record.notes) if running.kind == "map" else None,
                                "total": running.record.total if running.kind == "map" else None}
    return state


def _map_state(record) -> Optional[dict]:
    if record is None:
        return None
    return {"id": record.id, "label": record.label, "status": record.status, "error": record.error,
            "done": len(record.notes), "total": record.total, "seconds": record.seconds,
            "before": record.before.id if record.before else None, "summary": present.summary(record),
            "advice": record.advice_status, "advice_error": record.advice_error,
            "advice_progress": record.advice_progress,
            "dress": record.dress_status, "dress_error": record.dress_error, "dress_progress": record.dress_progress}


def _player_state(study: Study) -> dict:
    """The player's report and its calibration, for the page (the scale: None until found)."""
    with study.lock:
        calibration = study.calibration or {}
        return {"heard": len(study.heard), "version": study.heard_version, "status": study.calibration_status,
                "scale": calibration.get("attack_scale"), "calibrated_map": study.calibrated_map}


def create_app(study: Study, *, port: int, host: Optional[str] = None, allow_hosts: Iterable[str] = (),
               token: Optional[str] = None) -> FastAPI:
    """The studio's application around a Study; port (and host, when given) are where it is
    served, for the Host checks. With a host, every request needs the token (app.state.token:
    the one given, else a random one)."""
    app = FastAPI(title="fretbuzz studio", docs_url=None, redoc_url=None, openapi_url=None)
    env = templates()
    guard = Guard(port, host, allow_hosts, token)
    app.state.study = study
    app.state.token = guard.token

    @app.middleware("http")
    async def only_this_computer(request: Request, call_next):
        refused = guard.refuse(request)
        if refused is not None:
            return refused
        response = await call_next(request)
        response.headers["X-Content-Type-Options"] = "nosniff"
        response.headers["X-Frame-Options"] = "DENY"
        if guard.open and guard.has_token(request) == "query":
            response.set_cookie(guard.cookie, guard.token, httponly=True, samesite="strict")
        return response

    @app.exception_handler(BodyTooLarge)
    async def body_too_large(request: Request, e: BodyTooLarge):
        return refusal(413, f"refused: a request body over {MAX_BODY_BYTES} bytes", close=True)

    @app.exception_handler(NoSpace)
    async def no_space(request: Request, e: NoSpace):
        return JSONResponse({"error": str(e), "errors": {"export": str(e)}}, status_code=507)

    @app.exception_handler(OSError)
    async def cannot_write(request: Request, e: OSError):
        return JSONResponse({"error": f"the studio could not do it: {e}"}, status_code=500)

    @app.on_event("shutdown")
    def stop_the_worker() -> None:
        study.close()

    app.mount("/static", StaticFiles(directory=os.path.join(HERE, "static")), name="static")

    def page(name: str, **values) -> HTMLResponse:
        return HTMLResponse(env.get_template(name).render(**values))

    def record_of(map_id: Optional[int]):
        record = study.latest if map_id is None else study.maps.get(map_id)
        if record is None:
            raise InputError(f"map: {map_id} is not a map of this study")
        return record

    @app.exception_handler(FieldErrors)
    async def field_errors(request: Request, e: FieldErrors):
        return JSONResponse({"error": str(e), "errors": e.errors}, status_code=422)

    @app.exception_handler(InputError)
    async def input_error(request: Request, e: InputError):
        return JSONResponse({"error": str(e), "errors": {"form": str(e)}}, status_code=422)

    @app.get("/", response_class=HTMLResponse)
    def index() -> HTMLResponse:
        # The controls as the newest map left them (a reloaded page goes on from there).
        with study.lock:
            newest = study.maps[max(study.maps)]
        fret, offset = next(iter(newest.changes.get("fret_offsets", {}).items()), ("", ""))
        return page("index.html.j2", bench=study.base, setup=present.setup_rows(newest.bench),
                    settings=study.base.settings, strengths=newest.attacks, changes=newest.changes, fret=fret,
                    offset=offset, queue_limit=QUEUE_LIMIT, folder=study.folder, player=newest.attack_scale is not None,
                    practice=_core._setup_tolerance(study.base.instrument, ""))

    @app.get("/api/state")
    def state() -> JSONResponse:
        with study.lock:
            latest, done, version = study.latest, study.done, study.version
        shown = latest or done
        return JSONResponse({"version": version, "jobs": _jobs_state(study), "map": _map_state(latest),
                             "done": done.id if done else None, "advice": done.advice_status if done else "",
                             "dress": done.dress_status if done else "",
                             "advice_progress": done.advice_progress if done else "",
                             "dress_progress": done.dress_progress if done else "",
                             "setup": present.setup_rows(shown.bench) if shown else present.setup_rows(study.base),
                             "exports": list(study.exports), "player": _player_state(study)})

    @app.post("/api/what-if")
    async def what_if(request: Request) -> JSONResponse:
        job, superseded = study.submit_map(await _json(request))
        return JSONResponse({"id": job.id, "label": job.label, "total": job.record.total,
                             "superseded": [{"id": j.id, "label": j.label} for j in superseded]}, status_code=202)

    def tolerate(body) -> str:
        return body.get("tolerate", "") if isinstance(body, dict) else ""

    @app.post("/api/advice")
    async def advice(request: Request) -> JSONResponse:
        job, superseded = study.submit_advice(tolerate=tolerate(await _json(request)))
        return JSONResponse({"id": job.id if job else None, "map": study.done.id if study.done else None,
                             "superseded": [{"id": j.id, "label": j.label} for j in superseded]}, status_code=202)

    @app.post("/api/dress")
    async def dress(request: Request) -> JSONResponse:
        job, superseded = study.submit_advice("dress", tolerate(await _json(request)))
        return JSONResponse({"id": job.id if job else None, "map": study.done.id if study.done else None,
                             "superseded": [{"id": j.id, "label": j.label} for j in superseded]}, status_code=202)

    @app.post("/api/heard")
    async def heard(request: Request) -> JSONResponse:
        study.set_heard(await _json(request))
        return JSONResponse(_player_state(study))

    @app.post("/api/calibrate")
    async def calibrate(request: Request) -> JSONResponse:
        job, superseded = study.submit_calibration(tolerate(await _json(request)))
        return JSONResponse({"id": job.id if job else None,
                             "superseded": [{"id": j.id, "label": j.label} for j in superseded]}, status_code=202)

    @app.get("/fragment/player", response_class=HTMLResponse)
    def player_fragment() -> HTMLResponse:
        with study.lock:
            heard = [{"string": s, "fret": k, "strength": a, "heard": h} for (s, k, a), h in study.heard.items()]
            calibration, status = study.calibration, study.calibration_status
        return page("_player.html.j2", heard=heard, calibration=calibration, status=status,
                    error=study.calibration_error, calibrated_map=study.calibrated_map)

    @app.get("/fragment/maps", response_class=HTMLResponse)
    def maps(map: Optional[int] = None) -> HTMLResponse:
        record = study.latest if map is None else record_of(map)
        if record is None:
            return page("_maps.html.j2", record=None, before=None)
        with study.lock:
            heard = dict(study.heard)
        return page("_maps.html.j2", record=record, rows=present.map_rows(record, heard), summary=present.summary(record),
                    before=record.before, before_rows=present.map_rows(record.before, heard) if record.before else [])

    @app.get("/fragment/neck", response_class=HTMLResponse)
    def neck(map: Optional[int] = None) -> HTMLResponse:
        record = study.latest if map is None else record_of(map)
        return page("_neck.html.j2", views=present.neck_views(record.bench if record else study.base),
                    label=record.label if record else "as set up")

    @app.get("/fragment/advice", response_class=HTMLResponse)
    def advice_fragment(map: Optional[int] = None) -> HTMLResponse:
        record = study.done if map is None else record_of(map)
        return page("_advice.html.j2", record=record, advice=record.advice if record else None,
                    shop=present.shop(record.bench if record else study.base))

    @app.get("/fragment/dress", response_class=HTMLResponse)
    def dress_fragment(map: Optional[int] = None) -> HTMLResponse:
        record = study.done if map is None else record_of(map)
        return page("_dress.html.j2", record=record, dress=record.dress if record else None,
                    shop=present.shop(record.bench if record else study.base))

    @app.get("/fragment/note", response_class=HTMLResponse)
    def note(map: int, string: str, fret: int, strength: str) -> HTMLResponse:
        found = study.note(map, string, fret, strength)
        record = found["record"]
        plot = present.contacts_plot(found["played"], record.bench.settings["duration_s"], record.bench.frets)
        with study.lock:
            heard = study.heard.get((string, fret, strength), "")
        return page("_note.html.j2", record=record, note=found["verdict"], played=found["played"], plot=plot,
                    sentence=present.sentence(found["verdict"]), audio=found["audio"],
                    view=present.note_view(record.bench, string, fret), member=found["member"],
                    pluck_heard=found["played"]["heard"], heard=heard)

    @app.post("/api/export")
    async def export(request: Request) -> JSONResponse:
        body = await _json(request)
        map_id = body.get("map") if isinstance(body, dict) else None
        if map_id is not None and (isinstance(map_id, bool) or not isinstance(map_id, int)):
            raise FieldErrors({"export": "map: expected a map's number"})
        record = study.done if map_id is None else record_of(map_id)
        if record is None or record.status != "done":
            raise FieldErrors({"export": "export: no finished map yet; the report is made from a finished map"})
        relative = study.export_path(record)
        write_report(study, record, os.path.join(study.folder, relative), env)
        if relative not in study.exports:
            study.exports.append(relative)
        return JSONResponse({"url": f"/study/{relative}", "file": os.path.join(study.folder, relative)})

    @app.get("/study/{relative:path}")
    def study_file(relative: str) -> Response:
        try:
            path = study.path(relative)
        except StudyPathError as e:
            return JSONResponse({"error": f"refused: {e}"}, status_code=403)
        except FileNotFoundError:
            return JSONResponse({"error": f"not found: {relative}"}, status_code=404)
        return FileResponse(path, media_type=SERVED_SUFFIXES[os.path.splitext(path)[1].lower()])

    return app


# The report's sounds (Ogg Vorbis, base64) stop at this many bytes, so that the file stays
# under 2 MB however many notes the maps hold; the notes past it are drawn without a sound.
REPORT_SOUND_BYTES = 1_600_000


def _compressed_sound(study: Study, record, name: str) -> Optional[str]:
    """A note's WAV as a data: URL of Ogg Vorbis (None when it cannot be read)."""
    import tempfile
    from .. import _core
    try:
        wav = study.path(f"{record.folder}/{name}")
    except (OSError, StudyPathError):
        return None
    with tempfile.TemporaryDirectory(prefix="fretbuzz-report-") as scratch:
        out = os.path.join(scratch, "note.ogg")
        try:
            _core._compressed_audio(wav, out)
            with open(out, "rb") as f:
                return "data:audio/ogg;base64," + base64.b64encode(f.read()).decode("ascii")
        except (OSError, ValueError, RuntimeError):
            return None


def write_report(study: Study, record, path: str, env: Optional[Environment] = None) -> str:
    """The customer's report: one HTML file, dated, in the instrument file's units with mm
    beside: "As found" (the first map of the instrument as loaded, its set-up, its neck),
    "Recommended" (the advice and the fret dress, where they were asked for) and "After" (this
    map, marked against the one as found). Each note's sound is embedded as Ogg Vorbis (this
    map's first), up to REPORT_SOUND_BYTES."""
    import datetime
    from types import SimpleNamespace
    env = env or templates()
    found = study.as_found() or record
    after = record if record is not found else None
    if after is not None:  # each note of this map against the instrument as found
        compared = Bench.compare([{k: v for k, v in n.items() if k not in ("change", "before")} for n in record.notes],
                                 [{k: v for k, v in n.items() if k not in ("change", "before")} for n in found.notes])
        changes = {(c["string"], c["fret"], c["strength"]): c["change"] for c in compared.to_dict("records")}
        was = {(n["string"], n["fret"], n["strength"]): n for n in found.notes}
        after = SimpleNamespace(notes=[{**n, "change": changes.get((n["string"], n["fret"], n["strength"]), ""),
                                        "before": was.get((n["string"], n["fret"], n["strength"]))} for n in record.notes],
                                bench=record.bench, attacks=record.attacks, label=record.label)
    sounds: Dict[str, str] = {}
    used = 0
    for owner, key in ((record, "after"), (found, "found")):
        for n in owner.notes:
            if not n.get("audio") or used >= REPORT_SOUND_BYTES:
                continue
            sound = _compressed_sound(study, owner, n["audio"])
            if sound and used + len(sound) <= REPORT_SOUND_BYTES:
                sounds[f"{key}/{n['audio']}"] = sound
                used += len(sound)
    advice = record.advice or found.advice
    dress = record.dress or found.dress
    shop = present.shop(record.bench)
    html = env.get_template("report.html.j2").render(
        record=record, bench=record.bench, found=found, after=after,
        found_rows=present.map_rows(found), after_rows=present.map_rows(after) if after else [],
        found_summary=present.summary(found), after_summary=present.summary(after) if after else None,
        found_views=present.neck_views(found.bench), after_views=present.neck_views(record.bench) if after else [],
        found_setup=present.setup_rows(found.bench), after_setup=present.setup_rows(record.bench) if after else [],
        advice=advice, dress=dress, settings=record.bench.settings, sounds=sounds, shop=shop,
        units={"mm": "mm", "64ths": "64ths of an inch", "thousandths": "thousandths of an inch"}[record.bench.instrument.units],
        dated=datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z"))
    write_file(path, html.encode("utf-8"))
    return path


def write_file(path: str, data: bytes) -> None:
    """Writes path whole or not at all (a temporary file renamed over it, removed on failure);
    NoSpace when the disk is full."""
    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
        try:
            view = memoryview(data)
            while view:
                view = view[write_bytes(fd, view):]
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except OSError as e:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        if e.errno in (errno.ENOSPC, errno.EDQUOT):
            raise NoSpace(f"export: the disk of the study folder is full ({os.path.dirname(path)}): free some "
                          "space (`fretbuzz clean STUDY --keep-maps N` removes old maps) and export again") from None
        raise
