"""airgun-xl: ArtSim (ARL-TR-3559), the air gun impact simulator, as a Python package.

Load a shot from a workbook in the report's layout, run it, and get the result::

    import airgun_xl
    shot = airgun_xl.load("templates/shot_a.xlsx")
    result = shot.run()
    frame = result.to_frame()
"""
__version__ = "0.1.0"

from .errors import AirgunXlError, CellError, OptionError, OutputError, WorkbookError
from .params import ShotParams
from .result import Result
from .shot import Shot


def load(path):
    """Read a :class:`Shot` from a workbook (see :meth:`Shot.from_workbook`)."""
    return Shot.from_workbook(path)


__all__ = [
    "AirgunXlError",
    "CellError",
    "OptionError",
    "OutputError",
    "Result",
    "Shot",
    "ShotParams",
    "WorkbookError",
    "__version__",
    "load",
]
