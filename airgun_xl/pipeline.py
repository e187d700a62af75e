"""A fill from start to finish, shared by ``fill`` and ``design``: check, run, summarize,
write the workbook and the sidecar. Reports go through a ``warn`` callback."""
import dataclasses
import time

from . import __version__
from .checks import StabilityError, after_run, before_run
from .engine.summary import summarize
from .models import apply_model
from .workbook.atomic import check_output
from .workbook.sidecar import sidecar_path, write_history


@dataclasses.dataclass
class Options:
    integrator: str = "legacy"
    host: str = "excel"
    model: str = "4-mass"
    compare_models: bool = False
    force: bool = False
    allow_unstable: bool = False
    reproducible: bool = False
    track_all: bool = False  # record every step value (an archived run keeps them all)
    command: tuple = ()  # the command line, for provenance


@dataclasses.dataclass
class Filled:
    result: object
    summary: object
    stride: int
    sidecar: object
    compared: object = None  # the other model's Result, with --compare-models


def fill_workbook(shot, output, outputs, options, warn, started=None):
    """Run ``shot`` and write ``output`` (and its sidecar) as ``outputs`` selects.

    Raises
    ------
    AirgunXlError
        Before anything is written: an existing output, an unstable time step, divergence.
    """
    started = time.perf_counter() if started is None else started
    inputs = [shot.source.path] if shot.source is not None else []
    model_shot = dataclasses.replace(shot, params=apply_model(shot.params, options.model))
    rows = shot.params.rows
    sidecar = sidecar_path(output) if outputs.writes_sidecar(rows) else None
    check_output(output, options.force, inputs=inputs)  # before the run, not after
    if sidecar is not None:
        check_output(sidecar, options.force, inputs=inputs)
    warn(shot.warnings)
    crit, findings = before_run(model_shot.params, options.integrator)
    if crit.ratio > 1 and not options.allow_unstable:
        error = next(f for f in findings if f.level == "error")
        raise StabilityError(f"{error}; expected a smaller E2, --integrator newmark, or "
                             "--allow-unstable")
    warn(str(f) for f in findings if f.level != "note")
    result = model_shot.run(integrator=options.integrator, host=options.host,
                            track=outputs.tracked_series(sidecar is not None
                                                         or options.track_all))
    warn(result.warnings[len(shot.warnings):])
    warn(str(f) for f in after_run(result))
    compared = None
    if options.compare_models:
        other = "rigid" if options.model == "4-mass" else "4-mass"
        compared = dataclasses.replace(shot, params=apply_model(shot.params, other)).run(
            integrator=options.integrator, host=options.host, track=())
        compared = dataclasses.replace(compared, model=other)
    result = dataclasses.replace(result, model=options.model)
    needs_summary = outputs.groups & {"summary", "spectrum", "charts"}
    summary = summarize(result) if needs_summary else None
    info = {"version": __version__, "command": " ".join(options.command),
            "dt_crit": crit.dt_crit, "dt_ratio": crit.ratio, "compared": compared}
    if shot.source is not None:
        info.update(input=str(shot.source.path), sha256=shot.source.sha256)
    if not options.reproducible:
        info.update(kernel_seconds=result.history.kernel_seconds,
                    run_seconds=time.perf_counter() - started)
    warn(result.write(output, force=options.force, outputs=outputs, summary=summary, info=info))
    if sidecar is not None:
        write_history(result, sidecar)
    return Filled(result, summary, outputs.stride(rows), sidecar, compared)
