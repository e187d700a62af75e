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
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import OptionError
from ..units import PEAK_UNITS
from .pages import finite as pages_finite
from .pages import real

if TYPE_CHECKING:
    from starlette.requests import Request
    from starlette.responses import Response

#: Loopback names the server answers by default; ``--host`` adds its own.
LOOPBACK = ("127.0.0.1", "localhost", "::1", "[::1]")

#: The policy every response carries: nothing but the server's own files.
CSP = ("default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
       "object-src 'none'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'")

HEADERS = {"content-security-policy": CSP, "x-content-type-options": "nosniff",
           "referrer-policy": "no-referrer", "x-frame-options": "DENY",
           "cache-control": "no-store"}

_HERE = Path(__file__).parent


class Guard:
    """ASGI middleware: GET and HEAD only, and the security headers on every response."""

    def __init__(self, app: Any) -> None:
        self.app = app

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        started = False

        async def send_with_headers(message: Any) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
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
        try:
            await self.app(scope, receive, send_with_headers)
        except Exception as exc:  # noqa: BLE001 - an archive damaged while the view runs
            if started:
                raise
            from starlette.responses import PlainTextResponse

            # answered here, with the headers: Starlette's own 500 is sent outside this guard
            response = PlainTextResponse(f"the archive could not be read "
                                         f"({type(exc).__name__}): see airgun-xl archive "
                                         "verify\n", 500)
            await response(scope, receive, send_with_headers)


@dataclass(frozen=True)
class View:
    """What every page of one archive's view reads: the archive (read-only), its listing
    (read once, kept while the index is unchanged), the templates, the archive's label and
    the input cells a page may name. Kept in ``app.state.view``."""

    found: Any  # listing.read_only's archive
    listing: Any  # listing.Listing
    templates: Any  # starlette.templating.Jinja2Templates
    label: str
    known_cells: Any


# The endpoints are module-level plain functions: Starlette runs each in its thread pool, so
# a page that reads an entry from the disk does not hold another's request (the listing is
# shared under its lock); each reads the archive's :class:`View` from the application.

def _view(request: Request) -> View:
    view: View = request.app.state.view
    return view


def _page(request: Request, name: str, context: dict[str, Any], status: int = 200) -> Any:
    view = _view(request)
    return view.templates.TemplateResponse(request, name, {"archive": view.label, **context},
                                           status_code=status)


def _missing(request: Request, message: str) -> Any:
    return _page(request, "missing.html", {"message": message}, 404)


def _reading(request: Request, inputs: bool = False) -> Any:
    """While the first listing (or, with ``inputs``, the runs' inputs the index does not
    hold) is read: how far it is, 503 and a retry in a second (the page reloads itself: a
    meta refresh, no script)."""
    from starlette.responses import Response

    listing = _view(request).listing
    done, total = (listing.inputs_progress if inputs else listing.progress) or (0, 0)
    what = "the archive's runs' inputs" if inputs else "the archive's runs"
    if request.url.path == "/shots.csv":
        return Response(f"reading {what} ({done:,} of {total:,}): try again in a second\n",
                        503, media_type="text/plain")
    return _page(request, "reading.html", {"done": done, "total": total, "what": what}, 503)


def _inputs_for(request: Request, snapshot: Any, cells: set[str]) -> Any:
    """Every row's inputs ``cells`` read (None), or the page saying they are being read."""
    from .listing import indexed_cells

    needed = cells - {""} - set(indexed_cells())
    if needed and _view(request).listing.inputs_progress is not None:
        return _reading(request, inputs=True)
    for cell in needed:
        snapshot.with_inputs(cell)
    return None


def shots(request: Request, snapshot: Any) -> Response:
    """The shots page: the archive's runs, filtered, sorted and paged, with a scatter."""
    from . import pages
    from .listing import FIGURES

    view = _view(request)
    f = pages.filters(request.query_params)
    waiting = _inputs_for(request, snapshot, {f["x"], f["input"]})
    if waiting is not None:
        return waiting
    rows = pages.selected(snapshot, f)
    count = len(rows)
    last = max(1, math.ceil(count / pages.PAGE))
    at = min(max(1, int(pages.number(request.query_params.get("page")) or 1)), last)
    shown = [{"id": r["id"], "cells": [(key, pages.shown(r.get(key), factor, digits, key))
                                       for key, _h, _u, factor, digits in pages.COLUMNS],
              "warnings": r.get("warnings") or []}
             for r in rows[(at - 1) * pages.PAGE: at * pages.PAGE]]
    return _page(request, "shots.html", {
        "rows": shown, "columns": pages.COLUMNS, "count": count, "page": at,
        "pages": last, "f": f, "lots": snapshot.lots, "bad": snapshot.bad,
        "cells": view.known_cells, "figures": FIGURES, "colours": pages.COLOURS,
        "total": len(snapshot.rows), "taken": snapshot.taken,
        "scatter": json.dumps(pages.scatter(rows, f), allow_nan=False)})


def shots_csv(request: Request, snapshot: Any) -> Response:
    """What the shots page shows, as a CSV (every text a spreadsheet would run, as text)."""
    from starlette.responses import Response

    from . import pages

    view = _view(request)
    f = pages.filters(request.query_params)
    waiting = _inputs_for(request, snapshot, {f["input"]})
    if waiting is not None:
        return waiting
    rows = pages.selected(snapshot, f)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow([f"{h} [{u}]" if u else h for _k, h, u, _f, _d in pages.COLUMNS]
                    + ["warning texts"])
    for r in rows:  # a text that a spreadsheet would run is written as text
        writer.writerow([_csv_text(r.get(k)) if d is None else
                         ("" if r.get(k) is None else repr(r[k] * factor))
                         for k, _h, _u, factor, d in pages.COLUMNS]
                        + [_csv_text("; ".join(r.get("warnings") or []))])
    return Response(out.getvalue(), media_type="text/csv; charset=utf-8", headers={
        "content-disposition": f'attachment; filename="{_file_name(view.label)}-shots.csv"'})


def _entry_doc(view: View, snapshot: Any, ident: int) -> tuple[Any, Any]:
    """An entry's records as ``show`` reads them, and its predicted pulse."""
    from ..app.archive import predicted_pulse, show_entry

    entry = snapshot.entries.get(ident)
    if entry is None:
        raise LookupError(f"#{ident}: no such entry in {view.label}, expected an id the "
                          "shots page lists")
    outcome = show_entry(view.found, entry, snapshot.index_rows)
    return outcome.doc, predicted_pulse(entry)


def shot(request: Request) -> Response:
    """A shot's page: its figures, warnings, provenance, predicted pulse and verdicts."""
    from ..app.archive import shown_figure
    from ..errors import AirgunXlError
    from . import pages

    view = _view(request)
    ident = request.path_params["ident"]
    snapshot = view.listing.snapshot(wait=False) or view.listing.one(ident)
    try:
        doc, (time, accel) = _entry_doc(view, snapshot, ident)
    except (AirgunXlError, LookupError) as exc:
        return _missing(request, str(exc).strip("'\""))
    summary = dict(doc["summary"])
    warnings = summary.pop("warnings", None)
    predicted = summary.pop("predicted_verdict", None)
    figures = [shown_figure(k, v) for k, v in summary.items()]
    t, a = pages.thinned(time, accel)
    recorded = []
    start = pages.finite(summary.get("pulse_start"), 1e3)
    for v in snapshot.verdicts_of(snapshot.entries[ident]):
        shown = _verdict(view.found.root, v)
        chart = pages.verdict_chart((t, a), shown.pop("trace", None), start)
        shown["chart"] = chart and {**chart, "json": json.dumps(chart, allow_nan=False)}
        recorded.append(shown)
    predicted = predicted if isinstance(predicted, dict) else None
    band = _peak_band(predicted, recorded)
    return _page(request, "shot.html", {
        "doc": doc, "figures": figures, "warnings": warnings, "predicted": predicted,
        "recorded": recorded, "samples": len(time), "drawn": len(t), "band": band,
        "pulse": json.dumps({"time_ms": t, "accel_kg": a,
                             "band": [band["low"], band["high"]] if band else None},
                            allow_nan=False)})


def compare(request: Request, snapshot: Any) -> Response:
    """Shots side by side: the inputs that differ, their figures, their pulses overlaid."""
    from ..app.archive import FIGURE_UNITS, shown_figure
    from ..errors import AirgunXlError
    from . import pages

    view = _view(request)
    ids = pages.compared_ids(request.query_params)
    docs, pulses, refused = [], [], []
    for ident in ids:
        try:
            doc, pulse = _entry_doc(view, snapshot, ident)
        except (AirgunXlError, LookupError) as exc:
            refused.append(str(exc).strip("'\""))
            continue
        docs.append(doc)
        pulses.append(pulse)
    kept = [d["id"] for d in docs]
    differ, equal = pages.differing(docs)
    keys = [k for k in FIGURE_UNITS if any(k in d["summary"] for d in docs)]
    figures = [(shown_figure(k, None)[0], [shown_figure(k, d["summary"].get(k))[1]
                                           for d in docs]) for k in keys]
    drawn = pages.overlaid(pulses)
    return _page(request, "compare.html", {
        "docs": docs, "ids": kept, "refused": refused, "differ": differ, "equal": equal,
        "figures": figures, "max": pages.MAX_COMPARED,
        "candidates": [r for r in snapshot.rows if r["id"] not in kept][:500],
        "pulses": json.dumps({**drawn, "names": [d["entry"] for d in docs]},
                             allow_nan=False)})


def laws(request: Request, snapshot: Any) -> Response:
    """The laws page: each lot's law versions, its chain, P(PASS) against outcomes."""
    from . import pages

    view = _view(request)
    return _page(request, "laws.html",
                 _laws(view.found.root, snapshot, pages))


async def home(_request: Request) -> Response:
    from starlette.responses import RedirectResponse

    return RedirectResponse("/shots", 302)


def _listed(endpoint: Callable[[Request, Any], Response]) -> Callable[[Request], Response]:
    """``endpoint`` given the archive's listing (its snapshot), or, while the first listing
    is read, the page saying how far it is."""
    def answer(request: Request) -> Response:
        snapshot = _view(request).listing.snapshot(wait=False)
        return _reading(request) if snapshot is None else endpoint(request, snapshot)
    answer.__name__ = endpoint.__name__
    return answer


def _counted(endpoint: Callable[[Request], Response]) -> Callable[[Request], Response]:
    """``endpoint`` counted as a request in flight (:meth:`Listing.request`)."""
    def answer(request: Request) -> Response:
        with _view(request).listing.request():
            return endpoint(request)
    answer.__name__ = endpoint.__name__
    return answer


def build_app(archive: str | Path, hosts: tuple[str, ...] = (), warm: bool = True) -> Any:
    """The view of the archive at ``archive``, answering the loopback names and ``hosts``;
    ``warm``: its listing read in the background from the start."""
    import jinja2
    from starlette.applications import Starlette
    from starlette.middleware import Middleware
    from starlette.middleware.trustedhost import TrustedHostMiddleware
    from starlette.routing import Mount, Route
    from starlette.staticfiles import StaticFiles
    from starlette.templating import Jinja2Templates

    from . import pages
    from .listing import Listing, read_only

    found = read_only(archive)
    listing = Listing(found)
    if warm:
        listing.warm()
    templates = Jinja2Templates(env=jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(_HERE / "templates")), autoescape=True))
    templates.env.filters["safe_json"] = _script_json
    templates.env.globals.update(url=pages.url, compare_url=pages.compare_url)
    routes = [Route("/", home), Route("/shots", _counted(_listed(shots))),
              Route("/shots.csv", _counted(_listed(shots_csv))),
              Route("/shot/{ident:int}", _counted(shot)),
              Route("/compare", _counted(_listed(compare))),
              Route("/laws", _counted(_listed(laws))),
              Mount("/static", StaticFiles(directory=str(_HERE / "static")), name="static")]
    allowed = [h.strip("[]") if h.count(":") > 1 else h for h in (*LOOPBACK, *hosts)]
    app = Starlette(routes=routes, middleware=[
        Middleware(Guard), Middleware(TrustedHostMiddleware, allowed_hosts=allowed)])
    app.state.view = View(found, listing, templates, found.root.name, pages.cells())
    return app


def _verdict(root: Path, listed: dict[str, Any]) -> dict[str, Any]:
    """A recorded verdict of a shot as its page shows it: the record's criteria, or why it
    cannot be read."""
    from ..archive.records import read_record
    from ..archive.store import safe_name
    from ..archive.verdicts import VERDICTS
    from ..errors import ArchiveError

    path = (root / VERDICTS / safe_name(str(listed["folder"]))
            / f"v{int(listed['version']):04d}.json")
    try:
        record = read_record(root, path, "verdict")
    except ArchiveError as exc:
        return {"version": listed["version"], "verdict": "?", "problem": str(exc),
                "criteria": [], "by_name": listed["by_name"]}
    criteria = record.get("criteria") if isinstance(record, dict) else None
    return {"version": listed["version"], "verdict": str(record.get("verdict")),
            "by_name": listed["by_name"],
            "created": str(record.get("created", "")), "problem": None,
            "specification": str(record.get("specification", "")),
            "recording": str(record.get("recording", "")),
            "warnings": [str(w) for w in record.get("warnings") or []],
            "definitions": [str(d) for d in record.get("definitions") or []],
            "trace": record.get("trace"),
            "criteria": [c for c in criteria or [] if isinstance(c, dict)]}


def _peak_band(predicted: dict[str, Any] | None,
               recorded: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The peak's limits [kG] for the pulse chart: the latest recorded verdict's peak
    criterion, else the prediction's; None when neither judged a peak in kG or g."""
    sources = [(f"recorded verdict {v['version']}", v["criteria"]) for v in reversed(recorded)]
    if predicted:
        sources.append(("the prediction's specification", predicted.get("criteria") or []))
    for source, criteria in sources:
        for c in criteria:
            scale = PEAK_UNITS.get(str(c.get("unit"))) if c.get("unit") in ("kG", "g") \
                else None  # the one table of units: 1 g is 1/999.32 kG, not 1/1000
            if c.get("name") != "peak" or scale is None:
                continue
            low, high = (pages_finite(c.get(k), scale) for k in ("low", "high"))
            if low is not None or high is not None:
                return {"low": low, "high": high, "source": source}
    return None


def _intervals(given: Any) -> list[dict[str, Any]] | None:
    """A law record's nodes with their 95 % intervals, each value a finite number (a node
    that is not is left out); None when the record keeps none."""
    if not isinstance(given, list):
        return None
    out = []
    for node in given:
        if not isinstance(node, dict):
            continue
        values = {k: real(node.get(k)) for k in ("velocity", "value", "low", "high")}
        if None not in values.values():
            out.append({**values, "weak": node.get("weak") is True})
    return out


def _from_proposals(root: Path, lots: list[str]) -> tuple[
        dict[str, tuple[float, float | None]], dict[str, list[str]]]:
    """From the lots' proposals: each law version ``next`` made, with its scale on the lot's
    prior and that scale's standard error; and each proposal's warnings (what its P(PASS)
    cannot vouch for), by the proposal (``LOT@N``). A chain that cannot be read: none."""
    from ..archive.lots import proposals
    from ..errors import AirgunXlError

    scales: dict[str, tuple[float, float | None]] = {}
    warnings: dict[str, list[str]] = {}
    for lot in lots:
        try:
            chained = proposals(root, lot)
        except AirgunXlError:
            continue
        for version, record in chained:
            scale = real(record.get("scale"))
            if isinstance(record.get("law"), str) and scale is not None:
                scales[record["law"]] = (scale, real(record.get("scale_error")))
            said = record.get("warnings")
            warnings[f"{lot}@{version}"] = [str(w) for w in said] if isinstance(said, list) \
                else []
    return scales, warnings


def _laws(root: Path, snapshot: Any, pages: Any) -> dict[str, Any]:
    """The laws page: each lot's law versions (their ranges, curves, the shots each was fitted
    on and the entries that ran it), each lot's chain, and P(PASS) against outcomes."""
    from ..app.lot_chain import chain, expected_text, knobs_text, measured_text, said_once
    from ..app.next_shot import prediction_record
    from ..archive.laws import list_laws, load_law
    from ..errors import AirgunXlError

    lots: dict[str, dict[str, Any]] = {}
    scales, warned = _from_proposals(root, snapshot.lots)
    for law in list_laws(root):
        name = law["ref"].rpartition("@")[0]
        lot = lots.setdefault(name, {"name": name, "versions": [], "curves": [],
                                     "chain": [], "chain_problem": None})
        try:
            crush, record = load_law(root, law["ref"])
        except AirgunXlError as exc:
            lot["versions"].append({**law, "problem": str(exc), "coefficients": [],
                                    "fitted_on": [], "used_by": []})
            continue
        lot["curves"].append((law["ref"], crush))
        fitted = [s for s in record.get("shots") or [] if isinstance(s, dict)]
        lot["versions"].append({
            **law, "problem": None, "coefficients": list(crush.coefficients),
            "fitted_on": [{k: str(v) for k, v in s.items()} for s in fitted],
            "intervals": _intervals(record.get("intervals")),
            "scale": scales.get(law["ref"]),
            "used_by": [(r["id"], r["ref"]) for r in snapshot.rows if r.get("law") == law["ref"]]})
    for name in snapshot.lots:
        lot = lots.setdefault(name, {"name": name, "versions": [], "curves": [], "chain": [],
                                     "chain_problem": None})
    for name, lot in lots.items():
        try:
            rows = chain(root, name)
            carried = [warned.get(str(r["proposal"]), []) for r in rows]
            lot["chain"] = [{**r, "warnings": new, "repeats": repeats, "warned": bool(ws),
                             "expected_text": expected_text(r.get("expected_before")),
                             "measured_text": measured_text(r.get("measured")),
                             "next_text": knobs_text(r)}
                            for r, ws, (new, repeats) in zip(rows, carried,
                                                             said_once(carried), strict=True)]
        except AirgunXlError as exc:
            lot["chain_problem"] = str(exc) if "has no chain" not in str(exc) else None
        intervals = {v["ref"]: v.get("intervals") or [] for v in lot["versions"]}
        lot["chart"] = json.dumps(pages.law_curves(lot.pop("curves"), intervals),
                                  allow_nan=False)
    try:
        predictions: Any = prediction_record(root)
        problem = None
    except AirgunXlError as exc:
        predictions, problem = None, str(exc)
    return {"lots": [lots[k] for k in sorted(lots)], "record": predictions,
            "record_problem": problem}


def _script_json(text: str) -> Any:
    """JSON text made safe inside a ``<script type="application/json">`` element: no ``<``,
    ``>`` or ``&`` left to end the element or start markup (JSON's own escapes for them)."""
    from markupsafe import Markup

    return Markup(text.replace("<", "\\u003c").replace(">", "\\u003e")
                  .replace("&", "\\u0026"))


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

    try:
        info = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
    except (socket.gaierror, UnicodeError) as exc:
        raise OptionError(f"host: found {host!r}, which does not resolve ({exc}), expected "
                          "an address of this machine such as 127.0.0.1") from None
    sock = socket.socket(info[0], socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(info[4])
        sock.listen(64)
    except OSError as exc:
        sock.close()
        raise OptionError(f"port: {host}:{port} cannot be listened on ({exc.strerror}), "
                          "expected a free port (another server holds this one?)") from None
    return sock


#: What serve says when its extra is missing.
MISSING = ("serve: needs the web extra (Starlette, uvicorn, Jinja2), expected it installed: pip "
           "install 'airgun-xl[web]'")


def _warn(text: str) -> None:
    import sys

    print(f"airgun-xl: warning: {text}", file=sys.stderr, flush=True)


def is_loopback(host: str) -> bool:
    """Whether ``host`` is a loopback address or name (127.0.0.0/8, ::1, localhost): a view
    there is reached from this machine only."""
    import ipaddress

    if host in LOOPBACK:
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:  # a name: only localhost is sure to be loopback
        return False


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
    try:
        import jinja2  # noqa: F401 - each is needed: checked before anything starts
        import starlette  # noqa: F401
        import uvicorn
    except ImportError:
        raise OptionError(MISSING) from None
    if not 0 <= port <= 65535:
        raise OptionError(f"port: found {port}, expected a port from 0 to 65535")
    sock = listen(host, port)  # first: a refusal comes alone, before the archive is opened
    try:
        app = build_app(archive, () if host in LOOPBACK else (host,))
    except BaseException:
        sock.close()
        raise
    if not is_loopback(host):
        warn(f"--host {host}: the view answers on that address, and it has no login: anyone "
             "who reaches it reads the archive")
    bound = sock.getsockname()
    shown = f"[{bound[0]}]" if ":" in bound[0] else bound[0]
    config = uvicorn.Config(app, log_level="critical", access_log=False, server_header=False,
                            lifespan="off")
    say(f"serving {Path(archive)} at http://{shown}:{bound[1]}/ (read-only; Ctrl-C stops)")
    try:
        uvicorn.Server(config).run(sockets=[sock])
    finally:
        sock.close()
