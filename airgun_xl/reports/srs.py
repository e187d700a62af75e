"""The ``srs`` command's workbook: the SRS sheets of a run (:mod:`airgun_xl.xlsx.srs_sheets`)."""
from ..xlsx.report import report_workbook
from ..xlsx.srs_sheets import add_srs_sheets


def write_srs(path, frequencies, spectrum, about, force=False, shot=None, requirement=None,
              warnings=None):
    """Write the SRS workbook (:func:`add_srs_sheets`): frequencies [Hz], the maximax response
    [kG]; ``about`` is a list of (label, text) lines for the head of the sheet (shot, Q,
    filter); ``warnings``, the run's, are listed under them."""
    with report_workbook(path, force) as wb:
        add_srs_sheets(wb, frequencies, spectrum, about, shot, requirement,
                       warnings=warnings)
