"""What each page of the view shows, from the archive's :class:`~.listing.Snapshot` and the
page's URL: plain data for its template and its charts' JSON (no Starlette here).

Every choice a page makes is in its URL (filters, sort, page, the scatter's axes and colours,
the compared entries), so a view survives a reload and can be sent to a colleague. A value the
URL gives that the page does not know is ignored (the default is shown), never an error page.
"""
from __future__ import annotations

import math
from typing import Any
from urllib.parse import urlencode

import numpy as np

from .listing import FIGURES, Snapshot

#: Rows of the shots page.
PAGE = 50

#: The most entries a compare page overlays.
MAX_COMPARED = 8

#: Points a chart draws at most per series (a pulse is thinned by a stride to this).
CHART_POINTS = 4000

#: Columns of the shots page and its CSV: (key, heading, unit, factor to the unit, digits).
COLUMNS = (("id", "#", "", 1.0, None), ("shot", "shot", "", 1.0, None),
           ("version", "version", "", 1.0, None), ("created", "created", "", 1.0, None),
           ("v0", "v0", "m/s", 1.0, 2), ("peak_kg", "peak", "kG", 1.0, 4),
           ("pulse_duration", "pulse duration", "ms", 1e3, 4),
           ("lot", "lot", "", 1.0, None), ("predicted", "predicted verdict", "", 1.0, None),
           ("verdict", "recorded verdict", "", 1.0, None),
           ("warning_count", "warnings", "", 1.0, 0), ("integrator", "integrator", "", 1.0,
                                                       None),
           ("crush_law", "crush law", "", 1.0, None))

#: What the shots page may be sorted by (its columns).
SORTS = tuple(c[0] for c in COLUMNS)

#: The scatter's colourings: URL value -> words.
COLOURS = {"": "none", "lot": "lot", "verdict": "recorded verdict",
           "predicted": "predicted verdict"}

#: The filters' URL names, in the order a URL lists them.
FILTER_KEYS = ("shot", "lot", "verdict", "since", "v0_min", "v0_max", "peak_min", "peak_max",
               "input", "input_min", "input_max", "sort", "desc", "x", "y", "colour", "logx",
               "logy")


def number(text: Any) -> float | None:
    """A finite number from a URL's text, else None (ignored)."""
    if text is None or not str(text).strip():
        return None
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def cells() -> dict[str, tuple[str, str]]:
    """Each parameter cell: address -> (label, unit)."""
    from ..cells import CELLS

    return {c.address: (c.label, c.unit) for c in CELLS}


def filters(query: Any) -> dict[str, Any]:
    """The shots page's choices from its URL, each kept as given (bad values: the default)."""
    from ..cells import address

    sort = query.get("sort", "id")
    known = cells()
    figure_keys = [k for k, *_ in FIGURES]
    speed = address("v31")  # the scatter's default x: the bird's speed
    x = query.get("x", speed)
    y = query.get("y", "peak_kg")
    colour = query.get("colour", "lot")
    return {"shot": query.get("shot", "").strip()[:200],
            "lot": query.get("lot", "").strip()[:200],
            "verdict": query.get("verdict", "") if query.get("verdict", "") in (
                "", "PASS", "FAIL", "NOT JUDGED", "none") else "",
            "since": query.get("since", "").strip()[:10],
            "v0_min": number(query.get("v0_min")), "v0_max": number(query.get("v0_max")),
            "peak_min": number(query.get("peak_min")),
            "peak_max": number(query.get("peak_max")),
            "input": query.get("input", "") if query.get("input", "") in known else "",
            "input_min": number(query.get("input_min")),
            "input_max": number(query.get("input_max")),
            "sort": sort if sort in SORTS else "id",
            "desc": query.get("desc", "") == "1",
            "x": x if x in known else speed, "y": y if y in figure_keys else "peak_kg",
            "colour": colour if colour in COLOURS else "lot",
            "logx": query.get("logx", "") == "1", "logy": query.get("logy", "") == "1"}


def url(path: str, f: dict[str, Any], **changes: Any) -> str:
    """``path`` with the filters ``f`` (changed by ``changes``) as its query; defaults left
    out."""
    merged = {**f, **changes}
    pairs = []
    for key in (*FILTER_KEYS, *[k for k in changes if k not in FILTER_KEYS]):
        value = merged.get(key)
        if value is None or value is False or value == "":
            continue
        pairs.append((key, "1" if value is True else repr(value) if isinstance(value, float)
                      else str(value)))  # a float in full: a link keeps the limit given
    return path + ("?" + urlencode(pairs) if pairs else "")


def selected(snapshot: Snapshot, f: dict[str, Any]) -> list[dict[str, Any]]:
    """The rows the filters select, sorted (a row without the sorted value last)."""
    def within(value: Any, lo: float | None, hi: float | None) -> bool:
        if lo is None and hi is None:
            return True
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return False
        return (lo is None or value >= lo) and (hi is None or value <= hi)  # a limit: within

    shot = f["shot"].lower()
    out = [r for r in snapshot.rows
           if (not shot or shot in str(r.get("shot", "")).lower())
           and (not f["lot"] or (r.get("lot") or "(none)") == f["lot"])
           and (not f["verdict"] or (r.get("verdict") or "none") == f["verdict"])
           and (not f["since"] or str(r.get("created", ""))[:10] >= f["since"])
           and within(r.get("v0"), f["v0_min"], f["v0_max"])
           and within(r.get("peak_kg"), f["peak_min"], f["peak_max"])
           and (not f["input"] or within(r["inputs"].get(f["input"]), f["input_min"],
                                         f["input_max"]))]
    key = f["sort"]
    present = [r for r in out if r.get(key) is not None]
    absent = [r for r in out if r.get(key) is None]
    present.sort(key=lambda r: (_sortable(r[key]), r["id"]), reverse=f["desc"])
    return present + absent


def _sortable(value: Any) -> tuple[int, Any]:
    """Numbers before texts, each as they compare (a hostile row of mixed types sorts too)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return (0, value)
    return (1, str(value))


#: Columns whose missing value is a "none" (no lot, no verdict), not a figure not available.
NONE_SAID = ("lot", "predicted", "verdict")


def shown(value: Any, factor: float = 1.0, digits: int | None = None, key: str = "") -> str:
    """A value as a cell shows it: ``n/a`` (or ``none`` in :data:`NONE_SAID`) when missing,
    numbers to ``digits``."""
    if value is None:
        return "none" if key in NONE_SAID else "n/a"
    if digits is None or isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    return f"{value * factor:,.{digits}f}"


def real(value: Any) -> float | None:
    """A number from an untrusted record, as it is: None where it is not a finite number."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def finite(value: Any, factor: float = 1.0) -> float | None:
    """A number for a chart's JSON: rounded to 6 significant decimals, None (a gap) where
    missing or not finite."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)):
        return None
    number = float(value) * factor
    return float(f"{number:.6g}") if math.isfinite(number) else None


def scatter(rows: list[dict[str, Any]], f: dict[str, Any]) -> dict[str, Any]:
    """The shots page's scatter: a figure (``y``) against an input (``x``), a series a
    group of ``colour``, the runs with warnings (or none recorded) a series of their own,
    named so; on a log axis, a value that is not positive is left out and counted."""
    known = cells()
    label, unit = known[f["x"]]
    fig = next(fig for fig in FIGURES if fig[0] == f["y"])
    groups: dict[str, list[tuple[float, float, int]]] = {}
    left_out = 0
    for r in rows:
        x = finite(r["inputs"].get(f["x"]))
        y = finite(r["figures"].get(f["y"]), fig[3])
        if x is None or y is None:
            left_out += 1
            continue
        if (f["logx"] and x <= 0) or (f["logy"] and y <= 0):
            left_out += 1
            continue
        name = (str(r.get(f["colour"]) or "none") if f["colour"] else "runs")
        count = r.get("warning_count")
        name += (" (warnings not recorded)" if count is None else " (with warnings)" if count
                 else "")  # a figure the tool cannot vouch for is flagged where it is drawn
        groups.setdefault(name, []).append((x, y, r["id"]))
    names = sorted(groups)
    points = sorted((x, y, ident, k) for k, name in enumerate(names)
                    for x, y, ident in groups[name])
    xs = [p[0] for p in points]  # one slot a run: runs at one x each keep their own
    series = []
    for k, name in enumerate(names):
        ys: list[float | None] = [p[1] if p[3] == k else None for p in points]
        series.append({"name": name, "points": len(groups[name]), "y": ys})
    return {"x": xs, "ids": [p[2] for p in points], "series": series, "logx": f["logx"],
            "logy": f["logy"],
            "x_label": f"{f['x']} {label} [{unit}]" if unit else f"{f['x']} {label}",
            "y_label": f"{fig[1]} [{fig[2]}]" if fig[2] else fig[1], "left_out": left_out}


def thinned(time: Any, values: Any, factor: float = 1.0) -> tuple[list[Any], list[Any]]:
    """A pulse for a chart: every ``stride``-th sample (at most :data:`CHART_POINTS`), time
    in ms."""
    step = max(1, math.ceil(len(time) / CHART_POINTS))
    return ([finite(t, 1e3) for t in time[::step]], [finite(a, factor) for a in values[::step]])


def overlaid(pulses: list[tuple[Any, Any]]) -> dict[str, Any]:
    """Several pulses on one time axis for a chart: the union of their thinned times, each
    pulse's values where it has a sample (a gap elsewhere)."""
    return merged([thinned(t, a) for t, a in pulses])


def merged(lines: list[tuple[list[Any], list[Any]]]) -> dict[str, Any]:
    """Lines of their own x values on one x axis: the union of their x, each line's value
    where it has one (a gap elsewhere); a point with no finite x is left out."""
    xs = sorted({x for t, _a in lines for x in t if x is not None})
    at = {x: k for k, x in enumerate(xs)}
    ys = []
    for t, a in lines:
        column: list[float | None] = [None] * len(xs)
        for x, y in zip(t, a, strict=False):
            if x is not None:
                column[at[x]] = y
        ys.append(column)
    return {"x": xs, "y": ys}


def verdict_chart(prediction: tuple[list[Any], list[Any]], trace: Any,
                  pulse_start_ms: float | None) -> dict[str, Any] | None:
    """A recorded verdict's chart: the record it judged (its kept trace) and the corridor's
    limits, over the predicted pulse, the record shifted so that the ideal pulse's start
    (placed by the verdict) falls on the prediction's pulse start; None without a trace.
    Every value of the trace is untrusted: a non-number is a gap."""
    if not isinstance(trace, dict) or not isinstance(trace.get("time_ms"), list):
        return None
    onset = finite(trace.get("onset_ms"))
    shift = finite(pulse_start_ms - onset) if onset is not None and pulse_start_ms is not None \
        else 0.0
    shift = shift or 0.0  # as shown: to 6 significant digits
    time = [None if (x := finite(t)) is None else float(f"{x + shift:.6g}")
            for t in trace["time_ms"]]
    lines = [prediction, (time, [finite(v) for v in trace.get("kg") or []])]
    names = ["predicted pulse", "record judged"]
    for key, words in (("upper_kg", "corridor upper"), ("lower_kg", "corridor lower")):
        if isinstance(trace.get(key), list):
            lines.append((time, [finite(v) for v in trace[key]]))
            names.append(words)
    return {**merged(lines), "names": names, "shift_ms": shift,
            "aligned": onset is not None and pulse_start_ms is not None,
            "samples": trace.get("samples") if isinstance(trace.get("samples"), int)
            else None, "thinned": str(trace.get("thinned", ""))}


#: What a run was made with besides its cells: provenance.json's key -> words.
RUN_SETTINGS = (("crush_law", "crush law"), ("integrator", "integrator"), ("model", "model"),
                ("unloading", "unloading"), ("engine", "airgun-xl"))


def differing(docs: list[dict[str, Any]]) -> tuple[list[dict[str, Any]], int]:
    """The inputs (cells, then the run's settings: crush law, integrator, model, unloading,
    version) whose values differ between the compared entries' records, and how many are
    equal (not listed)."""
    by_cell: dict[str, dict[str, Any]] = {}
    for k, doc in enumerate(docs):
        for p in doc["params"]:
            if not isinstance(p, dict):
                continue
            cell = str(p.get("cell"))
            item = by_cell.setdefault(cell, {"cell": cell, "label": str(p.get("label", "")),
                                             "unit": str(p.get("unit", "")),
                                             "values": [None] * len(docs)})
            item["values"][k] = p.get("value")
        for key, words in RUN_SETTINGS:
            value = doc["provenance"].get(key)
            if isinstance(value, dict):  # a crush law: its name (its coefficients follow it)
                value = value.get("name")
            item = by_cell.setdefault(key, {"cell": "", "label": words, "unit": "",
                                            "values": [None] * len(docs)})
            item["values"][k] = value
    differ = [item for item in by_cell.values() if len({repr(v) for v in item["values"]}) > 1]
    return differ, len(by_cell) - len(differ)


def compared_ids(query: Any) -> list[int]:
    """The entries a compare URL names (``id=3&id=7``), in order, each once, at most
    :data:`MAX_COMPARED`."""
    out: list[int] = []
    for text in query.getlist("id"):
        value = number(text)
        if value is not None and value == int(value) and 0 <= value < 2 ** 63 \
                and int(value) not in out:
            out.append(int(value))
    return out[:MAX_COMPARED]


def compare_url(ids: list[int]) -> str:
    return "/compare" + ("?" + urlencode([("id", i) for i in ids]) if ids else "")


def law_curves(versions: list[tuple[str, Any]],
               intervals: dict[str, list[dict[str, Any]]] | None = None) -> dict[str, Any]:
    """Each law version's crush factor against relative velocity over its own range from 0
    (:func:`~airgun_xl.crush_law.speeds_text`), on one velocity axis (a gap outside a
    version's range); a version with its nodes' intervals (``intervals``, by its reference)
    also gets their low and high ends as points."""
    if not versions:
        return {"x": [], "y": [], "names": []}
    lo = max(0.0, min(law.v_range[0] for _r, law in versions))
    hi = max(law.v_range[1] for _r, law in versions)
    xs = [finite(x) for x in np.linspace(lo, hi, 200)]
    lines, names = [], []
    for ref, law in versions:
        a, b = law.v_range
        lines.append((xs, [finite(law(x)) if x is not None and a <= x <= b else None
                           for x in xs]))
        names.append(ref)
        for end in ("low", "high"):
            nodes = (intervals or {}).get(ref) or []
            if nodes:
                lines.append(([finite(n["velocity"]) for n in nodes],
                              [finite(n[end]) for n in nodes]))
                names.append(f"{ref} nodes, 95 % {end}")
    return {**merged(lines), "names": names}
