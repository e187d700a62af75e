"""airgun-xl: ArtSim (ARL-TR-3559), the air gun impact simulator, as a Python package.

Load a shot from a workbook in the report's layout, run it, and get the result::

    import airgun_xl
    shot = airgun_xl.load("templates/shot_a.xlsx")
    result = shot.run()
    frame = result.to_frame()
"""
from __future__ import annotations

import os
from typing import TYPE_CHECKING

from .errors import (
    AirgunXlError,
    ArchiveError,
    CampaignError,
    CellError,
    DesignError,
    DivergenceError,
    OptionError,
    OutputError,
    ResourceError,
    StabilityError,
    WorkbookError,
)
from .version import __version__

if TYPE_CHECKING:
    from .params import ShotParams
    from .result import Result
    from .shot import Shot

#: Loaded on first use (PEP 562), so that ``airgun-xl`` can set up its signal handling before
#: numpy and the engine load.
_LAZY = {"ShotParams": "params", "Result": "result", "Shot": "shot"}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def load(path: str | os.PathLike[str]) -> Shot:
    """Read a :class:`Shot` from a workbook (see :meth:`Shot.from_workbook`)."""
    from .shot import Shot

    return Shot.from_workbook(path)


__all__ = [
    "AirgunXlError",
    "ArchiveError",
    "CampaignError",
    "CellError",
    "DesignError",
    "DivergenceError",
    "OptionError",
    "OutputError",
    "ResourceError",
    "StabilityError",
    "Result",
    "Shot",
    "ShotParams",
    "WorkbookError",
    "__version__",
    "load",
]
