"""The hub objects: a :class:`Shot` (parameters and where they came from) runs into a
:class:`airgun_xl.result.Result`, which the writers turn into files."""
from __future__ import annotations

import os
import time
from collections.abc import Collection
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from .choices import HOSTS, TRACKED
from .crush_law import LEGACY_LAW, CrushLaw
from .engine import filtered_acceleration, get_integrator, test_item_derivatives
from .errors import OptionError
from .limits import check_memory, fill_bytes
from .params import ShotParams

if TYPE_CHECKING:
    import numpy as np

    from .engine.integrators import History
    from .result import Result


def last_mass(history: History, p: ShotParams) -> np.ndarray:
    """Displacement of the bird's last mass: Y33, or Y32 / Y31 for a reduced model."""
    return (history.y31, history.y32, history.y33)[p.bird_masses - 1]


def check_run_options(host: str, track: Collection[str]) -> None:
    """``host`` is one of :data:`HOSTS` and ``track`` holds names of ``TRACKED`` only.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    if host not in HOSTS:
        raise OptionError(f"host: found {host!r}, expected one of {', '.join(HOSTS)}")
    if isinstance(track, str):
        raise OptionError(f"track: found the string {track!r}, expected a collection of names "
                          f"from {', '.join(TRACKED)}")
    unknown = sorted(set(track) - set(TRACKED), key=str)
    if unknown:
        raise OptionError(f"track: found {unknown[0]!r}, expected names from "
                          f"{', '.join(TRACKED)}")


@dataclass
class Shot:
    """One shot: checked parameters, their source workbook (if any), and reading warnings.

    Parameters
    ----------
    params : ShotParams
    source : airgun_xl.readers.shot_workbook.Source or None
        The workbook the parameters were read from; None for a shot built in code.
    warnings : list of str
        What reading the workbook found worth saying (e.g. stale cached formula values).
    spec : airgun_xl.specification.Specification or None
        What the shot must meet: its workbook's Specification sheet (issue 25), or None.
    test : dict
        The test it is (:mod:`airgun_xl.identification`): its Specification sheet's Test
        block, field -> text.
    """

    params: ShotParams
    source: Any = None
    warnings: list[str] = field(default_factory=list)
    spec: Any = None
    test: dict[str, str] = field(default_factory=dict)

    @classmethod
    def from_workbook(cls, path: str | os.PathLike[str], read_law: bool = True) -> Shot:
        """Read a shot from a workbook in the report's layout; with ``read_law`` False, its
        Crush law sheet is left unread and the macro's law runs.

        Raises
        ------
        airgun_xl.errors.AirgunXlError
            A :class:`~airgun_xl.errors.CellError` naming the cell, or a
            :class:`~airgun_xl.errors.WorkbookError` for the file.
        """
        from .readers.shot_workbook import read_params, read_spec

        params, source, warnings = read_params(path, read_law)
        spec, test, found = read_spec(source)
        return cls(params, source, warnings + found, spec, test)

    def with_params(self, **changes: float) -> Shot:
        """The same shot with some parameters changed (checked again)."""
        return Shot(self.params.replace(**changes), self.source, list(self.warnings),
                    self.spec, dict(self.test))

    def with_law(self, law: CrushLaw | None) -> Shot:
        """The same shot with another crush-factor law (None: the macro's, Eq. 8)."""
        return Shot(self.params.replace(crush_law=law or LEGACY_LAW), self.source,
                    list(self.warnings), self.spec, dict(self.test))

    def run(self, integrator: str = "legacy", host: str = "excel",
            track: Collection[str] = TRACKED) -> Result:
        """Time-step the shot and derive the macro's columns.

        Parameters
        ----------
        integrator : str
            Name in :data:`airgun_xl.engine.INTEGRATORS`; ``"legacy"`` is ArtSim's scheme.
        host : {"excel", "calc"}
            Whose Offset rounding the filtered column reproduces when ``1/(E2*E34)`` is not a
            whole number.
        track : collection of str
            Step values to record (:data:`airgun_xl.engine.integrators.TRACKED`); the others
            are None in the result.

        Returns
        -------
        airgun_xl.result.Result

        Raises
        ------
        airgun_xl.errors.OptionError
            For an unknown integrator, host or tracked name.
        airgun_xl.errors.ResourceError
            Before stepping, when the run's estimated memory passes what is available
            (:func:`airgun_xl.limits.check_memory`).
        """
        from .result import Result

        p = self.params
        check_run_options(host, track)
        check_memory(fill_bytes(p.rows, len(track)),
                     f"a run of {p.rows:,} rows ({len(track)} step values tracked)",
                     "fewer rows (a larger E2 or a shorter E6) or fewer step values in track")
        started = time.perf_counter()
        history = get_integrator(integrator)(p, track)
        last = last_mass(history, p)  # the test item, or the last mass of a reduced model
        accel, vel, kg = test_item_derivatives(last, p.delta)
        filtered = filtered_acceleration(last, p.delta, p.samplerate, host)
        return Result(self, integrator, history, accel, vel, kg, filtered,
                      list(self.warnings) + filtered.warnings,
                      time.perf_counter() - started)
