"""``airgun-xl recording FILE``: the channels a recording holds, as the reading commands read
them (name, unit, rate, samples, start); ``--channel`` takes a name or a number from this."""
from .recording_options import RECORDING_HELP
from .run_options import add_json


def add_parser(sub):
    p = sub.add_parser("recording", help="list a recording's channels (name, unit, rate, "
                                         "samples, start)",
                       description="List the channels of a recording file as accept, "
                                   "compare-measured, calibrate and next read them: each "
                                   "one's name (or its number) for --channel, its unit as the "
                                   "file states it, its rate, length and first sample's time.")
    p.add_argument("recording", metavar="RECORDING", help=RECORDING_HELP)
    add_json(p, "the file's format and channels")
    p.set_defaults(run=run)


def run(args):
    from ..app.recording import run as recording

    outcome = recording(args.recording)
    print(outcome.to_json() if args.json else "\n".join(outcome.lines()))
    return 0
