"""The web view's application: its pages, its guards, and the server that runs it.

Safe by default (issue 48):

- only GET and HEAD are answered (405 otherwise), and only for a Host the server was started
  for (the loopback names, or ``--host``): a DNS-rebinding request gets 400;
- the SQLite index is opened read-only (SQLite's ``mode=ro``); an entry is found by its id in
  the index, and its folder and files are read only as ``show`` reads them (no link
  followed, nothing outside the archive);
- every text from the archive is escaped by Jinja2; data for a chart is JSON in a
  ``<script type="application/json">`` element, never interpolated into code;
- every response carries ``Content-Security-Policy: default-src 'self'``: the page loads
  nothing from anywhere but the server.
"""
from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Any

#: Loopback names the server answers by default; ``--host`` adds its own.
LOOPBACK = ("127.0.0.1", "localhost", "::1", "[::1]")

#: Rows of the shots page.
PAGE = 50

#: What the shots page may be sorted by (its columns).
SORTS = ("id", "shot", "version", "created", "v0", "peak_kg", "pulse_duration",
         "warning_count")

#: The policy every response carries: nothing but the server's own files.
CSP = ("default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
       "object-src 'none'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'")

HEADERS = {"content-security-policy": CSP, "x-content-type-options": "nosniff",
           "referrer-policy": "no-referrer", "x-frame-options": "DENY",
           "cache-control": "no-store"}

#: Columns of the shots page and its CSV: (key, heading, unit, factor to the unit, digits).
COLUMNS = (("id", "#", "", 1.0, None), ("shot", "shot", "", 1.0, None),
           ("version", "version", "", 1.0, None), ("created", "created", "", 1.0, None),
           ("v0", "v0", "m/s", 1.0, 2), ("peak_kg", "peak", "kG", 1.0, 4),
           ("pulse_duration", "pulse duration", "ms", 1e3, 4),
           ("warning_count", "warnings", "", 1.0, 0), ("integrator", "integrator", "", 1.0,
                                                       None),
           ("crush_law", "crush law", "", 1.0, None))

_HERE = Path(__file__).parent


class Guard:
    """ASGI middleware: GET and HEAD only, and the security headers on every response."""

    def __init__(self, app: Any) -> None:
        self.app = app

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def send_with_headers(message: Any) -> None:
            if message["type"] == "http.response.start":
                headers = [(k, v) for k, v in message.get("headers", [])
                           if k.decode("latin-1").lower() not in HEADERS]
                headers += [(k.encode(), v.encode()) for k, v in HEADERS.items()]
                message = {**message, "headers": headers}
            await send(message)

        if scope["method"] not in ("GET", "HEAD"):
            from starlette.responses import PlainTextResponse

            response = PlainTextResponse("only GET and HEAD: this view is read-only\n", 405,
                                         headers={"allow": "GET, HEAD"})
            await response(scope, receive, send_with_headers)
            return
        await self.app(scope, receive, send_with_headers)


def _number(text: str | None) -> float | None:
    if text is None or not text.strip():
        return None
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _filters(query: Any) -> dict[str, Any]:
    """The shots page's filters from its URL, each kept as given (bad values ignored)."""
    sort = query.get("sort", "id")
    return {"shot": query.get("shot", "").strip()[:200],
            "since": query.get("since", "").strip()[:10],
            "v0_min": _number(query.get("v0_min")), "v0_max": _number(query.get("v0_max")),
            "peak_min": _number(query.get("peak_min")),
            "peak_max": _number(query.get("peak_max")),
            "sort": sort if sort in SORTS else "id",
            "desc": query.get("desc", "") == "1"}


def _selected(rows: list[dict[str, Any]], f: dict[str, Any]) -> list[dict[str, Any]]:
    def within(value: Any, lo: float | None, hi: float | None) -> bool:
        if lo is None and hi is None:
            return True
        if not isinstance(value, (int, float)):
            return False
        return (lo is None or value >= lo) and (hi is None or value <= hi)

    out = [r for r in rows
           if (not f["shot"] or f["shot"].lower() in str(r.get("shot", "")).lower())
           and (not f["since"] or str(r.get("created", ""))[:10] >= f["since"])
           and within(r.get("v0"), f["v0_min"], f["v0_max"])
           and within(r.get("peak_kg"), f["peak_min"], f["peak_max"])]
    key = f["sort"]
    present = [r for r in out if r.get(key) is not None]
    absent = [r for r in out if r.get(key) is None]  # no value: last, whichever way
    present.sort(key=lambda r: (r[key], r["id"]), reverse=f["desc"])
    return present + absent


def _shown(value: Any, factor: float, digits: int | None) -> str:
    if value is None:
        return "n/a"
    if digits is None or not isinstance(value, (int, float)):
        return str(value)
    return f"{value * factor:,.{digits}f}"


def build_app(archive: str | Path, hosts: tuple[str, ...] = ()) -> Any:
    """The view of the archive at ``archive``, answering the loopback names and ``hosts``."""
    from starlette.applications import Starlette
    from starlette.middleware import Middleware
    from starlette.middleware.trustedhost import TrustedHostMiddleware
    from starlette.requests import Request
    from starlette.responses import RedirectResponse, Response
    from starlette.routing import Mount, Route
    from starlette.staticfiles import StaticFiles
    from starlette.templating import Jinja2Templates

    from ..app.archive import history_rows, predicted_pulse, show_entry, shown_figure
    from ..archive import Archive
    from ..archive.index import SqliteIndex
    from ..errors import AirgunXlError

    found = Archive(archive)
    if isinstance(found.index, SqliteIndex):
        found.index = SqliteIndex(found.root, read_only=True)
    import jinja2

    templates = Jinja2Templates(env=jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(_HERE / "templates")), autoescape=True))
    templates.env.filters["safe_json"] = _script_json
    label = found.root.name

    def rows_for(request: Request) -> tuple[dict[str, Any], list[dict[str, Any]]]:
        f = _filters(request.query_params)
        return f, _selected(history_rows(found.entries()), f)

    async def shots(request: Request) -> Response:
        f, rows = rows_for(request)
        pages = max(1, math.ceil(len(rows) / PAGE))
        page = min(max(1, int(_number(request.query_params.get("page")) or 1)), pages)
        shown = [[(key, _shown(r.get(key), factor, digits)) for key, _h, _u, factor, digits
                  in COLUMNS] + [("id_raw", r["id"])] for r in
                 rows[(page - 1) * PAGE: page * PAGE]]
        query = {k: ("" if v is None else ("1" if v is True else "" if v is False else v))
                 for k, v in f.items()}
        return templates.TemplateResponse(request, "shots.html", {
            "archive": label, "rows": shown, "columns": COLUMNS, "count": len(rows),
            "page": page, "pages": pages, "f": query,
            "points": json.dumps([[r.get("v0"), r.get("peak_kg"), r["id"]] for r in rows],
                                 allow_nan=False)})

    async def shots_csv(request: Request) -> Response:
        _f, rows = rows_for(request)
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow([f"{h} [{u}]" if u else h for _k, h, u, _f2, _d in COLUMNS])
        for r in rows:  # a text that a spreadsheet would run is written as text
            writer.writerow([_csv_text(r.get(k)) if d is None else
                             ("" if r.get(k) is None else repr(r[k] * factor))
                             for k, _h, _u, factor, d in COLUMNS])
        return Response(out.getvalue(), media_type="text/csv; charset=utf-8", headers={
            "content-disposition": f'attachment; filename="{_file_name(label)}-shots.csv"'})

    async def shot(request: Request) -> Response:
        ident = request.path_params["ident"]
        try:
            outcome = show_entry(found, f"#{ident}")
            entry = found.get(f"#{ident}")
            time, accel = predicted_pulse(entry)
        except AirgunXlError as exc:
            return templates.TemplateResponse(request, "missing.html", {
                "archive": label, "message": str(exc)}, status_code=404)
        doc = outcome.doc
        summary = dict(doc["summary"])
        warnings = summary.pop("warnings", None)
        summary.pop("predicted_verdict", None)
        figures = [shown_figure(k, v) for k, v in summary.items()]
        step = max(1, len(time) // 4000)  # the chart draws at most ~4,000 points
        pulse = json.dumps({"time_ms": [_finite(t, 1e3) for t in time[::step]],
                            "accel_kg": [_finite(a) for a in accel[::step]]}, allow_nan=False)
        return templates.TemplateResponse(request, "shot.html", {
            "archive": label, "doc": doc, "figures": figures, "warnings": warnings,
            "pulse": pulse})

    async def home(_request: Request) -> Response:
        return RedirectResponse("/shots", 302)

    routes = [Route("/", home), Route("/shots", shots), Route("/shots.csv", shots_csv),
              Route("/shot/{ident:int}", shot),
              Mount("/static", StaticFiles(directory=str(_HERE / "static")), name="static")]
    allowed = [h.strip("[]") if h.count(":") > 1 else h for h in (*LOOPBACK, *hosts)]
    return Starlette(routes=routes, middleware=[
        Middleware(Guard), Middleware(TrustedHostMiddleware, allowed_hosts=allowed)])


def _script_json(text: str) -> Any:
    """JSON text made safe inside a ``<script type="application/json">`` element: no ``<``,
    ``>`` or ``&`` left to end the element or start markup (JSON's own escapes for them)."""
    from markupsafe import Markup

    return Markup(text.replace("<", "\\u003c").replace(">", "\\u003e")
                  .replace("&", "\\u0026"))


def _finite(value: Any, factor: float = 1.0) -> float | None:
    """A number for a chart's JSON: rounded to 6 decimals, None (a gap) where not finite."""
    number = float(value) * factor
    return round(number, 6) if math.isfinite(number) else None


def _csv_text(value: Any) -> str:
    """Text for the CSV: one a spreadsheet would run as a formula gets a leading quote."""
    text = "" if value is None else str(value)
    return "'" + text if text[:1] in ("=", "+", "-", "@", "\t", "\r") else text


def _file_name(label: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in label)[:60] or "archive"


def listen(host: str, port: int) -> Any:
    """A socket bound to ``host``:``port`` (0: any free port), or one line saying why not.

    Raises
    ------
    OptionError
        The port is in use, or the host is not this machine's.
    """
    import socket

    from ..errors import OptionError

    try:
        info = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
    except (socket.gaierror, UnicodeError) as exc:
        raise OptionError(f"--host: found {host!r}, which does not resolve ({exc}), expected "
                          "an address of this machine such as 127.0.0.1") from None
    sock = socket.socket(info[0], socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(info[4])
        sock.listen(64)
    except OSError as exc:
        sock.close()
        raise OptionError(f"--port: {host}:{port} cannot be listened on ({exc.strerror}), "
                          "expected a free port (another server holds this one?)") from None
    return sock


#: What serve says when its extra is missing.
MISSING = ("serve: needs the web extra (Starlette, uvicorn, Jinja2), expected it installed: pip "
           "install 'airgun-xl[web]'")


def _warn(text: str) -> None:
    import sys

    print(f"airgun-xl: warning: {text}", file=sys.stderr, flush=True)


def serve(archive: str | Path, host: str = "127.0.0.1", port: int = 8765,
          say: Any = print, warn: Any = _warn) -> None:
    """Run the view of ``archive`` until Ctrl-C (SIGINT) or SIGTERM; ``say`` is told the
    address once the server listens, ``warn`` that a ``host`` other than loopback opens a
    page without a login.

    Raises
    ------
    OptionError
        The extra missing, a port out of range or in use, a host that does not resolve.
    """
    from ..errors import OptionError

    try:
        import jinja2  # noqa: F401 - each is needed: checked before anything starts
        import starlette  # noqa: F401
        import uvicorn
    except ImportError:
        raise OptionError(MISSING) from None
    if not 0 <= port <= 65535:
        raise OptionError(f"--port: found {port}, expected 0 to 65535")
    if host not in LOOPBACK:
        warn(f"--host {host}: the view answers on that address, and it has no login: anyone "
             "who reaches it reads the archive")
    app = build_app(archive, () if host in LOOPBACK else (host,))
    sock = listen(host, port)
    bound = sock.getsockname()
    shown = f"[{bound[0]}]" if ":" in bound[0] else bound[0]
    config = uvicorn.Config(app, log_level="critical", access_log=False, server_header=False,
                            lifespan="off")
    say(f"serving {Path(archive)} at http://{shown}:{bound[1]}/ (read-only; Ctrl-C stops)")
    try:
        uvicorn.Server(config).run(sockets=[sock])
    finally:
        sock.close()
