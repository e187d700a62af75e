"""The xlsx floor every workbook is written on: an xlsxwriter Workbook with the project's
fixed options and properties (the same run gives the same bytes; strings stay text), and its
close, whose failures are one :class:`~airgun_xl.errors.OutputError` line."""
import datetime

import xlsxwriter

from ..errors import OutputError
from ..transaction import display
from .columns_sheet import fast_deflate
from .safe_text import BOOLEAN_FORMAT, WORKBOOK_OPTIONS, SafeWorksheet

#: Fixed document properties, so the same run gives the same bytes.
PROPERTIES = {
    "title": "ArtSim results",
    "subject": "Air gun impact simulation (ARL-TR-3559)",
    "author": "airgun-xl",
    "company": "",
    "comments": "Written by airgun-xl",
    "created": datetime.datetime(2005, 8, 1),
}

class _Workbook(xlsxwriter.Workbook):
    worksheet_class = SafeWorksheet  # every sheet's strings are text (safe_text)

    def add_worksheet(self, name=None, worksheet_class=None):
        ws = super().add_worksheet(name, worksheet_class)
        if getattr(self, "_boolean_format", None) is None:
            self._boolean_format = self.add_format({"num_format": BOOLEAN_FORMAT})
        ws.boolean_format = self._boolean_format
        return ws

    def close(self):
        """Open on a report page: when the report pages are selected (grouped, by
        :func:`~airgun_xl.xlsx.report.one_page`) and the active sheet is not one of them, the
        first of them becomes active, so the default print is the group and nothing else
        (xlsxwriter would otherwise select sheet 1 with them)."""
        sheets = self.worksheets()
        grouped = [ws for ws in sheets if ws.selected]
        if grouped and not sheets[self.worksheet_meta.activesheet].selected:
            grouped[0].activate()
        return super().close()


def new_workbook(path):
    """An xlsxwriter Workbook with the project's fixed options and properties; strings are
    never turned into formulas, links or numbers (:mod:`airgun_xl.xlsx.safe_text`)."""
    wb = _Workbook(str(path), dict(WORKBOOK_OPTIONS, in_memory=True))
    wb.set_properties(PROPERTIES)
    return wb


def close_workbook(wb, path):
    """Close (package) an xlsxwriter Workbook at deflate level 1; a full disk, a file-size
    limit or any other failure to write becomes one :class:`OutputError` line."""
    from xlsxwriter.exceptions import XlsxFileError

    try:
        with fast_deflate():
            wb.close()
    except OSError as exc:
        raise OutputError(f"{display(path)}: cannot be written ({exc.strerror or exc})") from None
    except XlsxFileError as exc:
        raise OutputError(f"{display(path)}: cannot be written ({exc})") from None
