"""What a filled workbook's Summary says of its run beside the figures: one typed record.

The fill (:mod:`airgun_xl.app.fill`) makes a :class:`Provenance`; the workbook writer
(:mod:`airgun_xl.reports.fill`) adds what only it knows (the rows on the sheets, the stride,
the shot's shown name) with :meth:`Provenance.written`; the Summary sheet
(:mod:`airgun_xl.xlsx.sheets`) reads its fields. A misspelt field is an error, not an empty
cell. A field left None is not shown (``Result.write`` fills without a provenance).
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .result import Result


@dataclasses.dataclass(frozen=True)
class Provenance:
    """The run behind a Summary.

    Attributes
    ----------
    version : str or None
        airgun-xl's version that ran it.
    command : str
        The command line, as typed.
    warnings : tuple of str
        Every warning of the run, in order (the Summary prints them and flags the figures
        they put in doubt).
    dt_crit, dt_compacted, dt_unloading : float or None
        Critical time steps [s] (airgun-xl check); ``inf`` where the integrator has none.
    dt_ratio : float or None
        The time step over the critical one [-].
    compared : Result or None
        The run shown beside this one (the other model, or the unloading quirk left out).
    srs_requirement : tuple or None
        (frequencies [Hz], levels [kG], Q [-]) of a design's SRS target: the SRS sheets.
    study_notes : tuple of str
        What the study behind a designed shot found (design --confidence).
    verdict : object or None
        The prediction judged by the specification (a ``studies.acceptance.Verdict``).
    input, sha256 : str or None
        The shot workbook read, and its SHA-256.
    kernel_seconds, run_seconds : float or None
        Time stepping alone, and the whole run before writing [s]; None with
        ``--reproducible``.
    sheet_rows, every : int or None
        Time rows written to the sheets, and the stride between them (set by the writer).
    shot : str or None
        The shot's file name as shown on every page (set by the writer).
    """

    version: str | None = None
    command: str = ""
    warnings: tuple[str, ...] = ()
    dt_crit: float | None = None
    dt_compacted: float | None = None
    dt_unloading: float | None = None
    dt_ratio: float | None = None
    compared: Result | None = None
    srs_requirement: tuple[Any, ...] | None = None
    study_notes: tuple[str, ...] = ()
    verdict: Any = None
    input: str | None = None
    sha256: str | None = None
    kernel_seconds: float | None = None
    run_seconds: float | None = None
    sheet_rows: int | None = None
    every: int | None = None
    shot: str | None = None

    def written(self, every: int, sheet_rows: int, shot: str | None) -> Provenance:
        """This provenance with what the writer knows: the stride, the rows on the sheets and
        the shot's shown name."""
        return dataclasses.replace(self, every=every, sheet_rows=sheet_rows, shot=shot)
