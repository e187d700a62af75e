"""ASAM MDF (.mf4, and MDF 3 .mdf), by asammdf (the ``mdf`` extra, LGPL), in a process of its
own: each channel that is not a time base is a channel, named as the file names it, on its own
group's time base (channels at different rates keep theirs), its values the physical ones
(the file's conversion applied, raw=False) in the unit its conversion or channel states.

asammdf's compiled parts crash the process on some damaged files (a segmentation fault in
3 of 4 runs of 500 damaged copies of a two-channel file, asammdf 8.8.28), which no ``except``
can turn into one line. So the file is parsed in a child process (a fresh interpreter, the same on
Windows and macOS, which imports nothing of the caller's script): a crash, a hang past
:data:`TIMEOUT` or any error there is one line here, and nothing the library prints reaches
the terminal (the child's standard error goes nowhere).
A file past :data:`airgun_xl.limits.MAX_INPUT_BYTES` (up to
:data:`airgun_xl.limits.MAX_WINDOWED_BYTES`) is not read whole: the child opens it itself,
checked to be the very file the caller vetted (:func:`~airgun_xl.readers.guard.open_large`),
and reads only its metadata and the chosen channel. A channel of more than
:data:`airgun_xl.limits.MAX_SAMPLES` samples is scanned a chunk at a time and only the stretch
around its pulse is read (:func:`~.channels.pulse_window`), said in the reading's notes.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from ..guard import LargeFile
from .channels import ChannelInfo, Table, check_finite

NAME = "ASAM MDF"
SUFFIXES = (".mf4", ".mdf")
EXPECTED = "expected an ASAM MDF file (.mf4) with a channel of acceleration"

#: A file past :data:`airgun_xl.limits.MAX_INPUT_BYTES` is opened by the reader, not read whole.
WINDOWED = True

#: Seconds the child may take to read a file before it is stopped.
TIMEOUT = 120.0


#: A file of several channels: ``--channel`` chooses one.
SEVERAL = True


def named(path: str | Path) -> bool:
    """Whether the file's name is this format's: its suffix."""
    return Path(path).suffix.lower() in SUFFIXES


def sniff(head: bytes) -> bool:
    """An MDF file starts with its identification block's ``MDF     ``."""
    return head[:8] == b"MDF     "


def _listing(mdf: Any) -> list[tuple[int, int, str, str, int]]:
    """(group, index, name, unit, cycles) of every channel that is not a time base."""
    out = []
    for g, group in enumerate(mdf.groups):
        cycles = int(group.channel_group.cycles_nr)
        master = mdf.masters_db.get(g)
        for c, channel in enumerate(group.channels):
            if c == master or int(getattr(channel, "channel_type", 0)) in (2, 3):
                continue  # a master (time) channel, or a virtual one
            out.append((g, c, str(channel.name), str(channel.unit or ""), cycles))
    return out


def _ends(mdf: Any, g: int, cycles: int) -> tuple[float, float]:
    """The first and the last time [s] of group ``g``'s time base (two records read)."""
    first = np.asarray(mdf.get_master(g, record_offset=0, record_count=1), dtype=float)
    last = np.asarray(mdf.get_master(g, record_offset=cycles - 1, record_count=1), dtype=float)
    return float(first[0]), float(last[0])


def child(task: str, data: bytes, channel: str | None, large: dict[str, Any] | None = None,
          max_samples: int = limits.MAX_SAMPLES) -> tuple[dict[str, Any], list[Any]]:
    """Run in the child process: the reply's head (``kind`` ok, error, option or missing,
    and a ``result`` or ``text``) and its arrays. ``task`` is ``"list"`` (each channel's name,
    unit, cycles, rate [Hz] and start [s]) or ``"read"`` (the chosen channel's name and unit,
    the note of a window, and its time [s] and physical values as the arrays). ``large``: the
    fields of a :class:`~airgun_xl.readers.guard.LargeFile` the child opens itself (``data``
    then empty); ``max_samples``: the most samples read whole (the caller's cap)."""
    import io

    try:
        from asammdf import MDF
    except ImportError:
        return {"kind": "missing"}, []
    from ...errors import WorkbookError
    from ..guard import LargeFile, open_large
    from .channels import choose, pulse_window

    try:
        source = open_large(LargeFile(**large)) if large else io.BytesIO(data)
    except WorkbookError as exc:
        return {"kind": "said", "text": str(exc)}, []
    try:
        mdf = MDF(source)
        listing = _listing(mdf)
        if task == "list":
            out = []
            for g, _c, name, unit, cycles in listing:
                rate = start = None
                if cycles > 1:
                    t0, t1 = _ends(mdf, g, cycles)
                    if t1 > t0:
                        rate, start = (cycles - 1) / (t1 - t0), t0
                out.append([name, unit, cycles, rate, start])
            return {"kind": "ok", "result": out}, []
        if not listing:
            return {"kind": "error",
                    "text": f"has no channel of values (only time bases), {EXPECTED}"}, []
        try:
            g, c, name, unit, cycles = listing[choose(channel, [x[2] for x in listing])]
        except OptionError as exc:
            return {"kind": "option", "text": str(exc)}, []
        first, count, note = 0, None, ""
        if cycles > max_samples:  # scanned a chunk at a time, and its pulse's stretch read

            def values_at(offset: int, n: int) -> np.ndarray:
                got = np.asarray(mdf.get(group=g, index=c, raw=False, samples_only=True,
                                         record_offset=offset, record_count=n)[0])
                if got.dtype.kind not in "iuf":
                    raise TypeError(got.dtype)
                return got.astype(float)

            def times_at(offset: int, n: int) -> np.ndarray:
                return np.asarray(mdf.get_master(g, record_offset=offset, record_count=n),
                                  dtype=float)

            try:
                window = pulse_window(name, cycles, values_at, times_at, max_samples)
            except ValueError as exc:
                return {"kind": "error", "text": str(exc)}, []
            first, count, note = window.first, window.count, window.note
        signal = mdf.get(group=g, index=c, raw=False, record_offset=first, record_count=count)
        values = np.asarray(signal.samples)
        if values.dtype.kind not in "iuf":
            return {"kind": "error", "text": f"channel {name!r} holds {values.dtype} values "
                    f"(text or a structure), expected numbers, {EXPECTED}"}, []
        time = np.asarray(signal.timestamps, dtype="<f8")
        return ({"kind": "ok", "result": [name, str(signal.unit or unit), len(time),
                                          len(values), note]},
                [time, values.astype("<f8")])
    except Exception as exc:  # noqa: BLE001 - any failure on untrusted bytes: one line
        return {"kind": "error",
                "text": f"is not a readable MDF file ({type(exc).__name__}), {EXPECTED}"}, []
    finally:
        source.close()


def _main() -> None:
    """The child: a JSON line (task, channel) then the file's bytes on standard input; a JSON
    line then the arrays' float64 bytes on standard output. Nothing it or the library logs,
    warns or prints reaches the terminal (standard error goes nowhere)."""
    import json
    import logging
    import sys
    import warnings

    logging.disable(logging.CRITICAL)
    warnings.simplefilter("ignore")
    sys.unraisablehook = lambda _unraisable: None
    request = json.loads(sys.stdin.buffer.readline())
    head, arrays = child(request["task"], sys.stdin.buffer.read(), request["channel"],
                         request.get("large"), int(request["max_samples"]))
    out = sys.stdout.buffer
    out.write(json.dumps(head).encode() + b"\n")
    for array in arrays:
        out.write(np.ascontiguousarray(array, dtype="<f8").tobytes())
    out.flush()


def _in_child(path: str | Path, task: str, data: bytes | LargeFile, channel: str | None
              ) -> Any:
    """Run :func:`child` in a fresh interpreter (``python -m`` this module: the caller's
    script is not imported again, as multiprocessing's spawn would), and read its reply, a
    JSON head and float64 arrays whose lengths it checks; nothing is unpickled. ``data``: the
    file's bytes, or the large file the child opens itself."""
    import dataclasses
    import json
    import subprocess
    import sys

    shown = display(Path(path))
    large, data = ((dataclasses.asdict(data), b"") if isinstance(data, LargeFile)
                   else (None, data))
    request = {"task": task, "channel": channel, "large": large,
               "max_samples": limits.MAX_SAMPLES}
    try:
        done = subprocess.run([sys.executable, "-m", __name__],
                              input=json.dumps(request).encode() + b"\n" + data,
                              capture_output=True,
                              timeout=TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        raise WorkbookError(f"{shown}: the MDF reader (asammdf) took over {TIMEOUT:.0f} s on "
                            f"this file, {EXPECTED}") from None
    line, _, rest = done.stdout.partition(b"\n")
    if done.returncode != 0 or not line:
        raise WorkbookError(f"{shown}: the MDF reader (asammdf) stopped on this file (exit "
                            f"{done.returncode}), {EXPECTED}")
    try:
        head = json.loads(line)
        kind = head["kind"]
    except (ValueError, KeyError, TypeError):
        raise WorkbookError(f"{shown}: the MDF reader's reply is not readable, "
                            f"{EXPECTED}") from None
    if kind == "missing":
        raise OptionError(f"{shown}: reading MDF needs asammdf, expected it installed: pip "
                          "install 'airgun-xl[mdf]'")
    if kind == "option":
        raise OptionError(str(head.get("text", "--channel")))
    if kind == "said":  # already names the file
        raise WorkbookError(str(head.get("text", f"{shown}: changed while it was read")))
    if kind != "ok":
        raise WorkbookError(f"{shown}: {head.get('text', 'is not a readable MDF file')}")
    if task == "list":
        return head["result"]
    name, unit, n_time, n_values, note = head["result"]
    if not (n_time == n_values and len(rest) == 16 * n_time):
        raise WorkbookError(f"{shown}: channel {name!r} came back with {n_time:,} times and "
                            f"{n_values:,} values in {len(rest):,} bytes, {EXPECTED}")
    arrays = np.frombuffer(rest, dtype="<f8")
    return name, unit, arrays[:n_time].copy(), arrays[n_time:].copy(), str(note)


def channels(path: str | Path, data: bytes | LargeFile) -> list[ChannelInfo]:
    """The file's channels, each on its own group's time base."""
    return [ChannelInfo(name, unit, rate, cycles, start)
            for name, unit, cycles, rate, start in _in_child(path, "list", data, None)]


def read(path: str | Path, data: bytes | LargeFile, channel: str | None) -> Table:
    """The chosen channel (the first by default): its physical values on its time base (the
    stretch around its pulse of a channel past :data:`~airgun_xl.limits.MAX_SAMPLES`)."""
    shown = display(Path(path))
    name, unit, time, values, note = _in_child(path, "read", data, channel)
    if len(time) != len(values):
        raise WorkbookError(f"{shown}: channel {name!r} has {len(values):,} values and "
                            f"{len(time):,} times, {EXPECTED}")
    check_finite(shown, ((f"channel {name!r}", values), ("its time", time)))
    header = ["time [s]", f"acceleration [{unit}]" if unit else "acceleration"]
    return Table(f"{shown} ({name})", header, np.column_stack([time, values]),
                 (f"{shown}: {note}",) if note else ())


if __name__ == "__main__":
    _main()
