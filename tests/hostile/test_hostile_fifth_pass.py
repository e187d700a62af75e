"""Issue 59, the fifth hostile pass. Each test is named after its finding (59.N); a refusal
is exit 2, one line, no traceback, nothing written, nothing read outside the file named.

59.1: a MATLAB v7.3 (HDF5) recording can ask the HDF5 library to read another file: a
dataset's external storage, a virtual dataset, an external link (or a soft link through one),
or a filter HDF5 would load as a plugin. The outside file here is a FIFO watched by a thread:
HDF5 opens a file with a blocking open(), which waits for a writer, so any open of it is seen
(the watcher's non-blocking open for writing succeeds only while a reader holds it), and the
read is never left hanging.
"""
import os
import threading
from contextlib import contextmanager

import numpy as np
import pytest
from builders import mat73, matlab_double
from conftest import TEMPLATE
from support import refused

from airgun_xl.errors import WorkbookError
from airgun_xl.readers.recording import read_trace

h5py = pytest.importorskip("h5py")

POSIX = os.name == "posix"
pytestmark = pytest.mark.skipif(not POSIX, reason="a FIFO watches the outside file")

#: The samples of the good channel, 10 kHz.
N = 400
GOOD = np.sin(np.linspace(0.0, np.pi, N)) * 9.0


@contextmanager
def watched(fifo):
    """A FIFO at ``fifo`` and a list that gets an entry each time anything opens it to read."""
    os.mkfifo(fifo)
    stop, opened = threading.Event(), []

    def watch():
        while not stop.is_set():
            try:
                fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
            except OSError:  # ENXIO: no reader holds it
                stop.wait(0.0005)
                continue
            opened.append(True)
            os.close(fd)  # the reader sees the end of the file

    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    try:
        yield opened
    finally:
        stop.set()
        thread.join()


def _external_storage(f, name, outside):
    ds = f.create_dataset(name, shape=(1, N), dtype="<f8", external=[(outside, 0, N * 8)])
    ds.attrs["MATLAB_class"] = np.bytes_("double")


def _virtual(f, name, outside):
    layout = h5py.VirtualLayout(shape=(1, N), dtype="f8")
    layout[:] = h5py.VirtualSource(outside, "x", shape=(1, N))
    f.create_virtual_dataset(name, layout).attrs["MATLAB_class"] = np.bytes_("double")


def _external_link(f, name, outside):
    f[name] = h5py.ExternalLink(outside, "/x")


def _soft_link_through_an_external_one(f, name, outside):
    group = f.require_group("#refs#")
    group[f"out_{name}"] = h5py.ExternalLink(outside, "/")
    f[name] = h5py.SoftLink(f"/#refs#/out_{name}/x")


def _plugin_filter(f, name, outside):
    ds = f.create_dataset(name, data=GOOD.reshape(1, -1), chunks=(1, 100), compression=32004,
                          allow_unknown_filter=True)
    ds.attrs["MATLAB_class"] = np.bytes_("double")


#: Each way to make HDF5 read outside the file, and what the refusal says of it.
HOSTILE = {
    "external storage": (_external_storage, "HDF5 external storage"),
    "virtual dataset": (_virtual, "is a virtual dataset"),
    "external link": (_external_link, "is an external link"),
    "soft link through an external link": (_soft_link_through_an_external_one,
                                           "is a SoftLink"),
    "plugin filter": (_plugin_filter, "HDF5 filter 32004"),
}


def _recording(path, outside, hostile, good="first"):
    """A v7.3 recording at 10 kHz of the variables ``hostile`` ({name: kind}), with the good
    channel ``accel`` ``"first"``, ``"last"`` or not at all (None)."""
    def build(f):
        f.create_dataset("fs", data=np.array([[10_000.0]])).attrs["MATLAB_class"] = \
            np.bytes_("double")
        if good == "first":
            matlab_double(f, "accel", GOOD)
        for name, kind in hostile.items():
            HOSTILE[kind][0](f, name, str(outside))
        if good == "last":
            matlab_double(f, "accel", GOOD)

    return mat73(path, build)


@pytest.mark.parametrize("kind", sorted(HOSTILE))
def test_59_1_a_v73_recording_that_reads_an_outside_file_is_refused_unread(tmp_path, kind):
    """The hostile variable is the only channel (the one a command would read): refused in
    one line naming it and how it reaches outside, and the outside file never opened."""
    outside = tmp_path / "outside"
    path = _recording(tmp_path / "r.mat", outside, {"accel_x": kind}, good=None)
    with watched(outside) as opened:
        with pytest.raises(WorkbookError, match=f"variable 'accel_x'.*{HOSTILE[kind][1]}"):
            read_trace(path, channel="accel_x")
    assert opened == []


@pytest.mark.parametrize("command", ["recording", "accept", "compare-measured", "calibrate"])
def test_59_1_every_command_refuses_external_storage_and_writes_nothing(tmp_path, capsys,
                                                                          command):
    outside = tmp_path / "outside"
    path = _recording(tmp_path / "r.mat", outside, {"accel": "external storage"}, good=None)
    argv = {"recording": ["recording", path],
            "accept": ["accept", TEMPLATE, path, "--peak", "9kG:10%", "-o",
                       tmp_path / "v.xlsx"],
            "compare-measured": ["compare-measured", TEMPLATE, path, "-o",
                                 tmp_path / "c.xlsx"],
            "calibrate": ["calibrate", TEMPLATE, path, "-o", tmp_path / "k.xlsx"]}[command]
    with watched(outside) as opened:
        refused(capsys, argv, tmp_path, naming=("HDF5 external storage", "'accel'"))
    assert opened == []


def test_59_1_a_plain_v73_recording_is_still_read(tmp_path):
    """The vetting refuses nothing MATLAB writes: a plain file reads its samples exactly."""
    path = _recording(tmp_path / "r.mat", tmp_path / "unused", {})
    trace = read_trace(path, accel_unit="kG")
    assert np.array_equal(trace.accel_kg, GOOD)


def test_59_1_any_mix_of_hostile_variables_is_refused_before_a_read(tmp_path):
    """Under hypothesis (fixed seed): any set of hostile variables, named anything, before or
    after a good channel, refuses the file in one line naming one of them, and the outside
    file is never opened; with none, the good channel's samples are read exactly."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    names = st.text(st.sampled_from("abcxyz_019"), min_size=1, max_size=8).filter(
        lambda s: s.lower() not in {"accel", "fs", "time", "t", "dt", "t0"})
    mixes = st.dictionaries(names, st.sampled_from(sorted(HOSTILE)), max_size=3)

    @settings(max_examples=40, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(hostile=mixes, good=st.sampled_from(["first", "last"]))
    def check(hostile, good):
        for old in tmp_path.iterdir():
            old.unlink()
        outside = tmp_path / "outside"
        path = _recording(tmp_path / "r.mat", outside, hostile, good)
        with watched(outside) as opened:
            try:
                trace = read_trace(path, channel="accel", accel_unit="kG")
            except WorkbookError as exc:
                said = str(exc)
                assert hostile and "\n" not in said
                assert any(f"variable {name!r}" in said for name in hostile), said
            else:
                assert not hostile
                assert np.array_equal(trace.accel_kg, GOOD)
        assert opened == []

    check()


def test_59_2_a_virtual_dataset_mapping_another_file_crashes_nothing(tmp_path):
    """The crash: accept on a v7.3 channel that is a virtual dataset of another (real) HDF5
    file died with SIGSEGV every time. In a child process: one line, exit 2, nothing
    written."""
    from support import run_child

    source = tmp_path / "source.h5"
    with h5py.File(source, "w") as f:
        f["x"] = GOOD.reshape(1, -1)
    path = _recording(tmp_path / "r.mat", source, {"accel": "virtual dataset"}, good=None)
    out = tmp_path / "v.xlsx"
    code, err, _ = run_child(tmp_path, ["accept", TEMPLATE, path, "--peak", "9kG:10%",
                                        "-o", out])
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "is a virtual dataset" in lines[0], err
    assert not out.exists()
