"""``airgun-xl calibrate SHOT.xlsx RECORDING [SHOT2.xlsx RECORDING2 ...]``: the model
fitted to the shots that were fired."""
from pathlib import Path

from ..errors import OptionError
from .recording_options import add_recording_options
from .run_options import add_force, add_integrator, add_json, add_output
from .vocabulary import One


def add_parser(sub):
    p = sub.add_parser("calibrate", help="fit the crush-factor law, E40 or zeta to measured "
                                         "shots; write a workbook fill can run",
                       description="Recover the crush-factor law from one or more measured "
                                   "shots by the report's iteration (force over static crush "
                                   "force against relative velocity, refit, rerun, until the "
                                   "law moves < 1 %), then a least-squares finish; and/or fit "
                                   "E40, E43 (zeta) or the law's scale by least squares. "
                                   "Writes the first shot's workbook with the fitted values "
                                   "and a Crush law sheet that fill runs.")
    p.add_argument("pairs", nargs="+", metavar="SHOT.xlsx RECORDING",
                   help="each shot's workbook followed by its measured pulse (a CSV, "
                        "trace.xlsx:Sheet1!A:B or a TDMS file)")
    add_output(p, "the calibrated workbook", "SHOT.calibrated.xlsx")
    add_force(p)
    p.add_argument("--law", action="store_true",
                   help="recover the crush-factor law (the default when --fit is not given)")
    p.add_argument("--fit", metavar="NAMES",
                   help="fit these by least squares, comma-separated: E40, E43, scale "
                        "(E40 and scale exclude each other)")
    p.add_argument("--objective", choices=("l2", "iso18571"), default="l2",
                   help="what the least squares minimise: the filtered pulses' difference "
                        "(default) or 1 - the ISO/TS 18571 rating")
    p.add_argument("--degree", type=int, default=6, help="of the law's polynomial (1-6, "
                                                          "default 6 as Eq. 8)")
    add_recording_options(p, "TDMS only: the channel of every measured file (default: the "
                             "first waveform channel)")
    add_integrator(p)
    p.add_argument("--archive", metavar="DIR", action=One,
                   help="with --name: keep the fitted law in this archive's library of crush "
                        "laws (default: $AIRGUN_XL_ARCHIVE when set), for fill --crush-law NAME")
    p.add_argument("--name", metavar="NAME",
                   help="the law's name in the archive, e.g. LOT-2026-07 (a honeycomb lot); "
                        "storing it again adds its next version")
    add_json(p, "the calibration")
    p.set_defaults(run=run)


def _pairs(values):
    if len(values) % 2:
        raise OptionError(f"calibrate: found {len(values)} files, expected pairs of "
                          "SHOT.xlsx RECORDING")
    return tuple((values[i], values[i + 1]) for i in range(0, len(values), 2))


def request_of(args):
    """The :class:`~airgun_xl.app.calibrate.CalibrateRequest` the command line asks for
    (its default output beside the first shot)."""
    from ..app.calibrate import CalibrateRequest

    pairs = _pairs(args.pairs)
    first = Path(pairs[0][0])
    output = Path(args.output) if args.output else first.with_name(
        first.stem + ".calibrated.xlsx")
    return CalibrateRequest(pairs, args.law, args.fit, args.objective, args.degree, args.cfc,
                            args.sign, args.time_unit, args.accel_unit, args.channel,
                            args.anti_alias, args.integrator, output, args.force,
                            Path(args.archive) if args.archive else None, args.name,
                            tuple(args.argv), event=args.event, at=args.at)


def run(args):
    from ..app.calibrate import UNTRUSTED, lines
    from ..app.calibrate import run as calibrate
    from .messages import report

    request = request_of(args)
    outcome = calibrate(request)
    return report(outcome, lines(request, outcome), args.json,
                  0 if outcome.trusted else UNTRUSTED)
