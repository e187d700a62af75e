"""Deprecated: a shot workbook is read by :mod:`airgun_xl.readers.shot_workbook`."""
from ..readers.shot_workbook import *  # noqa: F403 - the old path's names, one release
from ..readers.shot_workbook import read_params, read_spec  # noqa: F401
from . import _moved

_moved("reader", "airgun_xl.readers.shot_workbook")
