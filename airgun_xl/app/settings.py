"""What ``fill``'s options ask of every shot, in a light module: the CLI builds it and a
campaign pickles it to its workers before the engine or the writers load."""
from __future__ import annotations

import dataclasses
from pathlib import Path

from ..specification import Specification


@dataclasses.dataclass(frozen=True)
class FillSettings:
    """What ``fill``'s options ask of each shot."""

    output: str | None = None  # one shot only; else SHOT.out.xlsx beside each
    force: bool = False
    host: str = "excel"
    only: str | None = None
    no_charts: bool = False
    every: str | None = None
    max_sheet_rows: str | None = None
    sidecar: str | None = None
    integrator: str = "legacy"
    allow_unstable: bool = False
    model: str = "4-mass"
    crush_law: str = "workbook"  # workbook, legacy, or a law of the archive's library
    unloading: str = "macro"
    compare_models: bool = False
    archive: str | None = None
    name: str | None = None
    reproducible: bool = False
    argv: tuple[str, ...] = ()
    # a tolerance profile (issue 25), under each shot's sheet: read once, before any shot
    profile: str | Specification | None = None
    spec: Specification | None = None  # the options' specification fields, over the sheet's
    pdf: str | None = None  # one shot only: its report as a PDF too


def default_output(shot_path: str | Path) -> Path:
    shot_path = Path(shot_path)
    return shot_path.with_name(shot_path.stem + ".out.xlsx")


def output_of(path: str | Path, settings: FillSettings) -> Path:
    """Where a shot is written: -o, or SHOT.out.xlsx beside it."""
    return Path(settings.output) if settings.output else default_output(Path(path))
