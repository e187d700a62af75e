"""``airgun-xl srs SHOT.xlsx``: the shock response spectrum of the predicted pulse."""
from pathlib import Path

from ..errors import OptionError
from .recording_options import CfcOption, cfc_value
from .run_options import SHOT_HELP, add_crush_law, add_force, add_output, add_run_options
from .vocabulary import Alias, One


def _q(text):
    """--srs-q: the one grammar of the SRS's quality factor (finite, above 0.5, at most
    1,000), as every command reads it."""
    from ..specification import parse_q

    return parse_q(text, "--srs-q")


def add_parser(sub):
    p = sub.add_parser("srs", help="shock response spectrum of the shot's predicted pulse",
                       description="Run the shot and write the maximax shock response "
                                   "spectrum of the test item's acceleration (Smallwood's "
                                   "ramp-invariant filter), as a table and a log-log chart.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    add_output(p, "the SRS workbook", "SHOT.srs.xlsx")
    add_force(p)
    p.add_argument("--srs-q", type=_q, default=10.0, metavar="Q", action=One,
                   help="quality factor (default 10: 5 %% damping)")
    p.add_argument("--q", type=_q, dest="srs_q", metavar="Q", action=Alias,
                   idea="SRS quality factor")
    p.add_argument("--cfc", type=cfc_value, action=CfcOption, metavar="N|none",
                   help="filter the pulse first: SAE J211 class 60, 180, 600 or 1000, or "
                        "none (the default)")
    p.add_argument("--from", dest="lo", type=float, default=100.0, metavar="HZ",
                   help="lowest natural frequency (default 100)")
    p.add_argument("--to", dest="hi", type=float, default=10_000.0, metavar="HZ",
                   help="highest natural frequency (default 10000)")
    add_run_options(p)
    add_crush_law(p)
    p.set_defaults(run=run)


def run(args):
    import dataclasses

    import numpy as np

    from ..archive.laws import shot_with_law
    from ..models import apply_model
    from ..reports.srs import write_srs
    from ..studies.check import after_run, before_run
    from ..studies.shock import (
        cfc_filter,
        default_frequencies,
        srs,
    )
    from ..transaction import check_output
    from .messages import warn

    if not (0 < args.lo < args.hi < float("inf")):
        raise OptionError(f"--from/--to: found {args.lo:g} and {args.hi:g} Hz, expected "
                          "0 < FROM < TO")
    shot = shot_with_law(args.shot, args.crush_law, args.archive)
    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".srs.xlsx")
    check_output(output, args.force, inputs=[args.shot])  # before the run, not after
    model_params = apply_model(shot.params, args.model)
    _, findings = before_run(model_params, args.integrator)
    result = dataclasses.replace(shot, params=model_params).run(integrator=args.integrator,
                                                                track=())
    # the warnings a fill of the shot gives, with the spectrum of its run (Summary-like),
    # each once (the checks and the run say a fractional 1/(E2*E34) in the same words)
    warnings = list(dict.fromkeys(
        [str(w) for w in shot.warnings] + [str(f) for f in findings if f.level != "note"]
        + [str(w) for w in result.warnings[len(shot.warnings):]]
        + [str(f) for f in after_run(result)]))
    pulse = result.accel_kg[np.isfinite(result.accel_kg)]
    dt = shot.params.delta
    if args.cfc is not None:
        pulse = cfc_filter(pulse, dt, args.cfc)
    freqs = default_frequencies(args.lo, args.hi)
    spectrum = srs(pulse, dt, freqs, args.srs_q)
    about = [("Shot", str(args.shot)), ("Quality factor Q", f"{args.srs_q:g}"),
             ("Filter", f"CFC {args.cfc}" if args.cfc else "none"),
             ("Model, integrator", f"{args.model}, {args.integrator}")]
    write_srs(output, freqs, spectrum, about, args.force, shot=shot_path.name,
              warnings=warnings)
    k = int(np.argmax(spectrum))
    print(f"wrote {output}: SRS at {len(freqs)} frequencies, {args.lo:g}-{args.hi:g} Hz, "
          f"Q = {args.srs_q:g}; largest {spectrum[k]:.4f} kG at {freqs[k]:,.0f} Hz")
    warn(warnings)
    return 0
