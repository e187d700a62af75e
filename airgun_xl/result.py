"""The result of a run: the macro's columns and the step values, as arrays and DataFrames."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import os

    import pandas as pd

    from .engine.filtered import Filtered
    from .engine.integrators import History
    from .params import ShotParams
    from .shot import Shot

#: DataFrame column -> unit, in the order of :meth:`Result.to_frame`.
FRAME_UNITS = {
    "y1": "m", "y31": "m", "y32": "m", "y33": "m", "crush_factor": "-", "m31": "kg",
    "deflection": "m", "x_plastic": "m", "force": "N", "m1": "kg", "v1": "m/s",
    "v31": "m/s", "accel": "m/s^2",
    "velocity": "m/s", "accel_kg": "kG", "filtered_accel": "m/s^2",
}


@dataclass
class Result:
    """A run of a :class:`airgun_xl.shot.Shot`.

    Attributes
    ----------
    shot : Shot
    integrator : str
    history : airgun_xl.engine.History
        Per-row values from the integrator.
    accel, velocity, accel_kg : numpy.ndarray
        Test-item acceleration [m/s^2], velocity [m/s] and acceleration [kG] (columns S, T, U).
    filtered : airgun_xl.engine.filtered.Filtered
        The filtered samples (column AB).
    warnings : list of str
    run_seconds : float
        Wall time of :meth:`Shot.run`: stepping and the derived columns [s].
    model : str
        The model variant that produced it (``4-mass`` or ``rigid``).
    """

    shot: Shot
    integrator: str
    history: History
    accel: np.ndarray
    velocity: np.ndarray
    accel_kg: np.ndarray
    filtered: Filtered
    warnings: list[str]
    run_seconds: float = float("nan")
    model: str = "4-mass"  # which model variant produced it (airgun_xl.models)

    @property
    def params(self) -> ShotParams:
        return self.shot.params

    @property
    def rows(self) -> int:
        """Number of time rows (the sheet's rows 2..rows+1)."""
        return len(self.history.time)

    @property
    def filtered_column(self) -> np.ndarray:
        """Filtered acceleration per row [m/s^2], NaN where the macro leaves AB empty."""
        out = np.full(self.rows, np.nan)
        inside = self.filtered.rows < self.rows
        out[self.filtered.rows[inside]] = self.filtered.values[inside]
        return out

    @property
    def peak_kg(self) -> float:
        """Largest value of the Acceleration (kG's) column."""
        return float(np.nanmax(self.accel_kg)) if np.isfinite(self.accel_kg).any() else np.nan

    @property
    def time_of_peak(self) -> float:
        """Time of :attr:`peak_kg` [s] (first row if it repeats)."""
        if not np.isfinite(self.accel_kg).any():
            return np.nan
        return float(self.history.time[int(np.nanargmax(self.accel_kg))])

    def frame_columns(self) -> dict[str, np.ndarray | None]:
        """Per-row arrays by :data:`FRAME_UNITS` name (None for series not tracked)."""
        h = self.history
        return {
            "y1": h.y1, "y31": h.y31, "y32": h.y32, "y33": h.y33,
            "crush_factor": h.crush_factor, "m31": h.m31, "deflection": h.deflection,
            "x_plastic": h.x_plastic, "force": h.force, "m1": h.m1, "v1": h.v1, "v31": h.v31,
            "accel": self.accel, "velocity": self.velocity, "accel_kg": self.accel_kg,
            "filtered_accel": self.filtered_column,
        }

    def to_frame(self) -> pd.DataFrame:
        """All per-row values as a pandas DataFrame indexed by time [s].

        Columns are those of :data:`FRAME_UNITS` (``v1``, ``v31``: MEM and OBR front plate
        velocities); ``frame.attrs["units"]`` maps each to its unit. Cells the macro leaves
        empty are NaN; series a run did not track are left out.
        """
        import pandas as pd

        data = {k: v for k, v in self.frame_columns().items() if v is not None}
        frame = pd.DataFrame(data, index=pd.Index(self.history.time, name="time"))
        frame.attrs["units"] = dict(FRAME_UNITS, time="s")
        frame.attrs["integrator"] = self.integrator
        return frame

    def write(self, path: str | os.PathLike[str], force: bool = False,
              **options: Any) -> list[str]:
        """Write the workbook (see :func:`airgun_xl.reports.fill.write_workbook`)."""
        from .reports.fill import write_workbook

        return write_workbook(self, path, force=force, **options)
