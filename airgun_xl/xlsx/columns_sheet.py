"""An xlsxwriter worksheet that also takes whole numeric columns, written fast.

xlsxwriter stores every cell as an object and writes it through a generic per-cell path, about
15 us a cell here: 2 s for the 150,000 result cells of shot A at 0.5 us, which was most of a
fill. :class:`ColumnsWorksheet` keeps numeric columns as arrays and renders them straight into
the ``<row>`` elements when xlsxwriter writes the sheet; everything else (labels, formulas,
sparse cells) still goes through xlsxwriter. Numbers are rendered in C
(``sheet_xml.render_cells``) with 17 significant digits, so every double reads back exactly
(xlsxwriter itself keeps 16).

It hooks ``Worksheet._write_rows``, an xlsxwriter internal; the legacy comparison tests read
every output back, so a change there cannot pass unnoticed.
"""
import threading
import zipfile
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager

import numpy as np
import xlsxwriter.workbook
import xlsxwriter.worksheet
from xlsxwriter.utility import xl_col_to_name

from .safe_text import SafeWorksheet
from .sheet_xml import render_cells

#: The xlsxwriter internals the fast path overrides or calls. They are there in every version
#: pyproject.toml allows (3.1.9 .. 3.x; CI runs the lowest and the newest); where one is
#: missing, :class:`ColumnsWorksheet` writes through xlsxwriter's public ``write_number``
#: instead, to the same cell values (see :class:`Exact`), only slower.
FAST = all(hasattr(xlsxwriter.worksheet.Worksheet, name) for name in (
    "_write_rows", "_write_row", "_write_empty_row", "_write_cell", "_check_dimensions",
    "_get_range_data")) and hasattr(xlsxwriter.workbook, "ZipFile")


class Exact(float):
    """A float that formats with 17 significant digits: xlsxwriter's public path writes
    numbers with ``f"{number:.16G}"``, which does not always read back as the same double.
    (Before 3.2 it formatted with ``%``, which no subclass can change; those versions have the
    internals, so the fallback is not used there.)"""

    def __format__(self, spec):
        return format(float(self), ".17g") if spec.upper().endswith("G") else format(
            float(self), spec)


def _row_properties(ws):
    """Row heights and formats by row: ``row_info`` from xlsxwriter 3.3, ``set_rows`` before."""
    return ws.row_info if hasattr(ws, "row_info") else ws.set_rows


#: Rows in a worksheet (Excel's limit; xlsxwriter refuses beyond it).
SHEET_ROWS = 1_048_576

#: Rows rendered at a time: bounds the memory of the rendered text.
CHUNK_ROWS = 8_192


class ColumnsWorksheet(SafeWorksheet):
    """Worksheet with :meth:`write_number_column` for long numeric columns."""

    def __init__(self):
        super().__init__()
        self._bulk = []  # (col, first_row, list of rendered <c> elements)
        self._bulk_formats = {}  # (col, first_row) of a run -> its cells' Format

    def write_number_column(self, first_row, col, values, cell_format=None):
        """Write finite numbers down column ``col`` from ``first_row`` (0-based), exactly
        (17 significant digits), with ``cell_format`` if given.

        Several calls may fill one column, in runs that do not overlap.

        Returns
        -------
        int
            0, or -1 when the column would pass the sheet's last row (nothing is written),
            as xlsxwriter's own write methods report it.

        Raises
        ------
        ValueError
            When a value is not finite (leave such cells out instead).
        """
        values = np.asarray(values, dtype=float)
        if len(values) == 0:
            return 0
        last = first_row + len(values) - 1
        if last >= SHEET_ROWS:
            return -1
        if not np.isfinite(values).all():
            raise ValueError("write_number_column takes finite numbers only")
        if not FAST:  # xlsxwriter's public path, to the same values
            for row, value in enumerate(values.tolist(), start=first_row):
                self.write_number(row, col, Exact(value), cell_format)
            return 0
        self._check_dimensions(first_row, col)
        self._check_dimensions(last, col)
        self._bulk.append((col, first_row, np.ascontiguousarray(values)))
        if cell_format is not None:
            self._bulk_formats[(col, first_row)] = cell_format
        return 0

    def _get_range_data(self, row_start, col_start, row_end, col_end):
        # Chart caches: none for ranges over bulk columns (as in xlsxwriter's constant_memory
        # mode); Excel and LibreOffice read the cells. Building it cost 0.15 s for shot A.
        for col, first, values in self._bulk:
            if col_start <= col <= col_end and first <= row_end and row_start < first + len(
                    values):
                return ()
        return super()._get_range_data(row_start, col_start, row_end, col_end)

    def _bulk_rows(self, lo, hi):
        """{row: (cols, cell texts)} of the bulk cells in rows [lo, hi), rendered in C on two
        threads, one dict per chunk of rows so that memory stays bounded."""
        runs = sorted((run for run in self._bulk
                       if run[1] < hi and lo < run[1] + len(run[2])), key=lambda run: run[0])
        pieces = [(col, max(first, lo), values[max(first, lo) - first:min(hi - first,
                                                                          len(values))])
                  for col, first, values in runs]
        styles = [self._bulk_formats.get((col, first)) for col, first, _ in runs]
        styles = [-1 if fmt is None else fmt._get_xf_index() for fmt in styles]
        with ThreadPoolExecutor(2) as pool:  # render_cells formats without the GIL
            texts = list(pool.map(lambda p: render_cells(xl_col_to_name(p[0]), p[1] + 1, p[2],
                                                         p[3]),
                                  [(*piece, style) for piece, style in zip(pieces, styles,
                                                                          strict=True)]))
        spans = [(col, first, first + len(values), t)
                 for (col, first, values), t in zip(pieces, texts, strict=True)]
        edges = sorted({s[1] for s in spans} | {s[2] for s in spans})
        rows = {}
        # the set of covering runs is fixed in [a, b)
        for a, b in zip(edges, edges[1:], strict=False):
            cover = [(col, t[a - first:b - first]) for col, first, end, t in spans
                     if first <= a and b <= end]
            if cover:
                cols = [col for col, _ in cover]
                for row, parts in enumerate(zip(*(t for _, t in cover), strict=True), start=a):
                    rows[row] = (cols, parts)
        return rows

    def _write_rows(self):
        if not self._bulk:
            return super()._write_rows()
        write = self.fh.write
        row_info = _row_properties(self)
        for lo in range(self.dim_rowmin, self.dim_rowmax + 1, CHUNK_ROWS):
            hi = min(lo + CHUNK_ROWS, self.dim_rowmax + 1)
            bulk = self._bulk_rows(lo, hi)
            for row in range(lo, hi):
                table = self.table.get(row)  # .get: the defaultdict must not grow
                cols, parts = bulk.get(row, ((), ()))
                if not parts and not table:
                    if row in row_info:
                        self._write_empty_row(row, None, row_info[row])
                    continue
                if row in row_info:
                    self._write_row(row, None, row_info[row])
                else:
                    write(f'<row r="{row + 1}">')
                if table:  # merge xlsxwriter's own cells in column order
                    by_col = dict(zip(cols, parts, strict=True))
                    for col in sorted(set(table) | set(cols)):
                        if col in table:
                            self._write_cell(row, col, table[col])
                        else:
                            write(by_col[col])
                else:
                    write("".join(parts))
                write("</row>")


class _FastZipFile(zipfile.ZipFile):
    """ZipFile at deflate level 1: a third of the time of the default level 6 for sheet XML
    that is about 30% larger."""

    def writestr(self, zinfo_or_arcname, data, compress_type=None, compresslevel=1):
        super().writestr(zinfo_or_arcname, data, compress_type, compresslevel)


_ZIP_LOCK = threading.Lock()


@contextmanager
def fast_deflate():
    """While closing an xlsxwriter Workbook, package it at deflate level 1.

    xlsxwriter has no compression option; its module-level ``ZipFile`` name is swapped for the
    duration of the block only, under a lock.
    """
    if not FAST:
        yield
        return
    with _ZIP_LOCK:
        saved = xlsxwriter.workbook.ZipFile
        xlsxwriter.workbook.ZipFile = _FastZipFile
        try:
            yield
        finally:
            xlsxwriter.workbook.ZipFile = saved
