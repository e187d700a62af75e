"""What a fill puts in the archive: inputs, outputs, history, figures and provenance."""
import dataclasses
import datetime
import platform
from pathlib import Path

import numpy as np

from ..blas import KERNEL, PINNED
from ..cells import CELLS
from ..crush_law import law_name
from ..reports.sidecar import have_parquet, render_history
from ..transaction import display
from ..version import __version__
from .store import safe_name

LIBRARIES = ("numpy", "pandas", "openpyxl", "xlsxwriter", "formulas", "python-calamine",
             "scipy", "pyarrow", "matplotlib")


def _versions():
    from importlib import metadata  # here: 11 ms that a fill without --archive does not pay

    out: dict[str, str | None] = {"python": platform.python_version(),
                                  "airgun-xl": __version__}
    for name in LIBRARIES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def _plain(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def shot_name(shot, given=None):
    """The archive name of a shot: ``given``, else the value beside a "Shot" label in the
    parameter sheet, else the input file's name."""
    if given:
        return given
    if shot.source is not None:
        for (row, col), (value, _) in sorted(shot.source.block.items()):
            if isinstance(value, str) and value.strip().lower() == "shot":
                name = shot.source.block.get((row, col + 1), (None, None))[0]
                if name not in (None, ""):
                    return str(name)
        return shot.source.path.stem
    return "shot"


def prepare_entry(archive, request, shot, workbook, filled, options, seconds):
    """Write a finished fill's archive entry to scratch; return the
    :class:`airgun_xl.archive.PendingEntry` that the fill's publication commits.

    Parameters
    ----------
    archive : airgun_xl.archive.Archive
    request : airgun_xl.app.fill.ArchiveRequest
    shot : airgun_xl.shot.Shot
    workbook : pathlib.Path
        The output workbook as written (its temp file, not yet published).
    filled : airgun_xl.app.fill.Filled
    options : airgun_xl.app.fill.Options
    seconds : float
        Run time so far [s].
    """
    p, result, s = shot.params, filled.result, filled.summary
    params = [{"cell": c.address, "label": c.label, "value": getattr(p, c.name),
               "unit": c.unit, "meaning": c.meaning} for c in CELLS]
    summary = {}
    if s is not None:
        summary = {k: _plain(v) for k, v in dataclasses.asdict(s).items() if k != "spectrum"}
        summary["dominant_frequencies_hz"] = list(s.spectrum.peaks)
    summary.update(rows=result.rows, peak_kg=_plain(result.peak_kg),
                   time_of_peak=_plain(result.time_of_peak), warnings=list(filled.warnings))
    if filled.verdict is not None:  # the prediction judged by the shot's specification
        v = filled.verdict
        summary["predicted_verdict"] = {
            "verdict": v.word, "specification": v.spec.source,
            "criteria": [{k: _plain(x) for k, x in dataclasses.asdict(c).items()}
                         for c in v.criteria],
            "tolerances": v.tolerances(), "definitions": v.definitions}
    provenance = {"engine": __version__, "versions": _versions(),
                  "input": display(shot.source.path) if shot.source else None,
                  "input_sha256": shot.source.sha256 if shot.source else None,
                  "started": request.started_at, "run_seconds": seconds,
                  "command": [display(a) for a in options.command],
                  "integrator": options.integrator, "model": options.model,
                  "unloading": p.unloading,
                  "crush_law": {"name": law_name(p.crush_law),
                                "coefficients": list(p.crush_law.coefficients),
                                "v_range": list(p.crush_law.v_range)},
                  "host": options.host, "stride": filled.stride,
                  "openblas": {"kernel": KERNEL, "pinned": PINNED}}
    files = {"output.xlsx": workbook}
    if shot.source is not None:
        files["input" + shot.source.path.suffix.lower()] = shot.source.path
    history = "history.parquet" if have_parquet() else "history.csv"
    index = {"input_sha256": provenance["input_sha256"], "v0": p.v31, "delta": p.delta,
             "max_time": p.max_time, "sigmay": p.sigmay, "rcone": p.rcone,
             "peak_kg": summary["peak_kg"], "integrator": options.integrator,
             "model": options.model, "engine": __version__,
             "warnings": len(filled.warnings)}
    return archive.prepare(
        safe_name(request.name), files,
        {"params.json": params, "summary.json": summary, "provenance.json": provenance},
        index, {history: lambda path: render_history(result, path, shown=Path(history))})


def now():
    return datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
