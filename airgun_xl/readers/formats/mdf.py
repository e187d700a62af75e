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
A channel's declared cycle count is checked against :data:`airgun_xl.limits.MAX_SAMPLES`
before its values are read.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from .channels import ChannelInfo, check_finite

NAME = "ASAM MDF"
SUFFIXES = (".mf4", ".mdf")
EXPECTED = "expected an ASAM MDF file (.mf4) with a channel of acceleration"

#: Seconds the child may take to read a file before it is stopped.
TIMEOUT = 120.0


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


def child(task: str, data: bytes, channel: str | None) -> tuple[dict[str, Any], list[Any]]:
    """Run in the child process: the reply's head (``kind`` ok, error, option or missing,
    and a ``result`` or ``text``) and its arrays. ``task`` is ``"list"`` (each channel's name,
    unit, cycles, rate [Hz] and start [s]) or ``"read"`` (the chosen channel's name and unit,
    and its time [s] and physical values as the arrays)."""
    import io

    try:
        from asammdf import MDF
    except ImportError:
        return {"kind": "missing"}, []
    from .channels import choose

    try:
        mdf = MDF(io.BytesIO(data))
        listing = _listing(mdf)
        if task == "list":
            out = []
            for g, _c, name, unit, cycles in listing:
                rate = start = None
                if 1 < cycles <= limits.MAX_SAMPLES:
                    t = np.asarray(mdf.get_master(g), dtype=float)
                    if len(t) > 1 and t[-1] > t[0]:
                        rate, start = (len(t) - 1) / (t[-1] - t[0]), float(t[0])
                out.append([name, unit, cycles, rate, start])
            return {"kind": "ok", "result": out}, []
        if not listing:
            return {"kind": "error",
                    "text": f"has no channel of values (only time bases), {EXPECTED}"}, []
        try:
            g, c, name, unit, cycles = listing[choose(channel, [x[2] for x in listing])]
        except OptionError as exc:
            return {"kind": "option", "text": str(exc)}, []
        if cycles > limits.MAX_SAMPLES:
            return {"kind": "error", "text": f"channel {name!r} holds {cycles:,} samples, "
                    f"expected at most {limits.MAX_SAMPLES:,} samples"}, []
        signal = mdf.get(group=g, index=c, raw=False)
        values = np.asarray(signal.samples)
        if values.dtype.kind not in "iuf":
            return {"kind": "error", "text": f"channel {name!r} holds {values.dtype} values "
                    f"(text or a structure), expected numbers, {EXPECTED}"}, []
        time = np.asarray(signal.timestamps, dtype="<f8")
        return ({"kind": "ok", "result": [name, str(signal.unit or unit), len(time),
                                          len(values)]},
                [time, values.astype("<f8")])
    except Exception as exc:  # noqa: BLE001 - any failure on untrusted bytes: one line
        return {"kind": "error",
                "text": f"is not a readable MDF file ({type(exc).__name__}), {EXPECTED}"}, []


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
    head, arrays = child(request["task"], sys.stdin.buffer.read(), request["channel"])
    out = sys.stdout.buffer
    out.write(json.dumps(head).encode() + b"\n")
    for array in arrays:
        out.write(np.ascontiguousarray(array, dtype="<f8").tobytes())
    out.flush()


def _in_child(path: str | Path, task: str, data: bytes, channel: str | None) -> Any:
    """Run :func:`child` in a fresh interpreter (``python -m`` this module: the caller's
    script is not imported again, as multiprocessing's spawn would), and read its reply, a
    JSON head and float64 arrays whose lengths it checks; nothing is unpickled."""
    import json
    import subprocess
    import sys

    shown = display(Path(path))
    try:
        done = subprocess.run([sys.executable, "-m", __name__],
                              input=json.dumps({"task": task, "channel": channel}).encode()
                              + b"\n" + data, capture_output=True, timeout=TIMEOUT,
                              check=False)
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
    if kind != "ok":
        raise WorkbookError(f"{shown}: {head.get('text', 'is not a readable MDF file')}")
    if task == "list":
        return head["result"]
    name, unit, n_time, n_values = head["result"]
    if not (n_time == n_values and len(rest) == 16 * n_time):
        raise WorkbookError(f"{shown}: channel {name!r} came back with {n_time:,} times and "
                            f"{n_values:,} values in {len(rest):,} bytes, {EXPECTED}")
    arrays = np.frombuffer(rest, dtype="<f8")
    return name, unit, arrays[:n_time].copy(), arrays[n_time:].copy()


def channels(path: str | Path, data: bytes) -> list[ChannelInfo]:
    """The file's channels, each on its own group's time base."""
    return [ChannelInfo(name, unit, rate, cycles, start)
            for name, unit, cycles, rate, start in _in_child(path, "list", data, None)]


def read(path: str | Path, data: bytes, channel: str | None) -> tuple[str, list[str],
                                                                      np.ndarray]:
    """The chosen channel (the first by default): its physical values on its time base."""
    shown = display(Path(path))
    name, unit, time, values = _in_child(path, "read", data, channel)
    if len(time) != len(values):
        raise WorkbookError(f"{shown}: channel {name!r} has {len(values):,} values and "
                            f"{len(time):,} times, {EXPECTED}")
    check_finite(shown, ((f"channel {name!r}", values), ("its time", time)))
    header = ["time [s]", f"acceleration [{unit}]" if unit else "acceleration"]
    return f"{shown} ({name})", header, np.column_stack([time, values])


if __name__ == "__main__":
    _main()
