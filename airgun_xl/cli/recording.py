"""``airgun-xl recording FILE``: the channels a recording holds, as the reading commands read
them (name, unit, rate, samples, start); ``--channel`` takes a name or a number from this.
Its argument is its request's field (:class:`airgun_xl.app.recording.RecordingRequest`)."""
from .declared import add_declared, request_of
from .run_options import add_json


def add_parser(sub):
    from ..app.recording import RecordingRequest

    p = sub.add_parser("recording", help="list a recording's channels (name, unit, rate, "
                                         "samples, start)",
                       description="List the channels of a recording file as accept, "
                                   "compare-measured, calibrate and next read them: each "
                                   "one's name (or its number) for --channel, its unit as the "
                                   "file states it, its rate, length and first sample's time.")
    add_declared(p, RecordingRequest)
    add_json(p, "the file's format and channels")
    p.set_defaults(run=run)


def run(args):
    from ..app.recording import RecordingRequest
    from ..app.recording import run as recording

    outcome = recording(request_of(RecordingRequest, args))
    print(outcome.to_json() if args.json else "\n".join(outcome.lines()))
    return 0
