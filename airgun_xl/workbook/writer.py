"""Deprecated: a result's workbook is written by :mod:`airgun_xl.reports.fill`."""
from ..reports.fill import *  # noqa: F403 - the old path's names, one release
from ..reports.fill import render_workbook, write_workbook  # noqa: F401
from . import _moved

_moved("writer", "airgun_xl.reports.fill")
