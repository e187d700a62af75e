"""Deprecated: recordings are read by :mod:`airgun_xl.readers.recording`."""
from ..readers.recording import *  # noqa: F403 - the old path's names, one release
from ..readers.recording import ACCEL_UNITS, TIME_UNITS, Trace, input_file, read_trace  # noqa: F401
from . import _moved

_moved("trace", "airgun_xl.readers.recording")
