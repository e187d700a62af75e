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
from pathlib import Path

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


# -- 59.3: next on a lot is a transaction -----------------------------------------------------

#: A specification shot A's lot 10 % stronger fails at first (tests/test_closed_loop.py's).
NEXT_SPEC = ["--peak", "8.5kG:5%", "--duration", "4.5ms:15%"]
#: Monte Carlo draws a setting: these tests look at the records, not at the probability.
NEXT_SHOTS = "100"
#: The confidence asked: these tests look at the records; with the model's own error drawn
#: (the prior's 5 % on the peak against a ±5 % tolerance) 0.95 is out of reach, and next
#: would exit 3.
NEXT_CONFIDENCE = "0.3"


def _fire(workbook, recording, seed):
    """The lab fires ``workbook`` on a lot 10 % stronger than the report's law."""
    from conftest import write_trace_csv

    import airgun_xl
    from airgun_xl.crush_law import LEGACY_LAW
    from airgun_xl.studies.calibrate import synthetic_measurement

    p = airgun_xl.load(workbook).params.replace(crush_law=LEGACY_LAW.scaled(1.10))
    return write_trace_csv(recording, synthetic_measurement(p, dt=1 / 51_200, seed=seed))


def _next_argv(shot, recording, archive, *extra):
    return ["next", shot, recording, "--archive", archive, "--lot", "LOT", "--sd", "A28=1.5%",
            "--shots", NEXT_SHOTS, "--confidence", NEXT_CONFIDENCE, *NEXT_SPEC, *extra]


@pytest.fixture(scope="module")
def lot_of_one(tmp_path_factory):
    """A lot LOT of one shot through next (the archive, the next workbook) and two
    recordings of that workbook fired: the two shots two calls race to add."""
    import openpyxl

    from airgun_xl.cli import main

    work = tmp_path_factory.mktemp("lot")
    shot1 = work / "shot1.xlsx"
    # shot A at a 2 us step (E2; the template's is 0.5 us): the peak moves 0.014 %, each
    # call of next costs a quarter of the kernel's time; these tests are of the archive's
    # chain, not of the numbers
    book = openpyxl.load_workbook(TEMPLATE)
    book.worksheets[0]["E2"] = 2e-6
    book.save(shot1)
    _fire(shot1, work / "rec1.csv", seed=3)
    argv = _next_argv(shot1, work / "rec1.csv", work / "arch", "--new-lot", "-o",
                      work / "shot2.xlsx")
    assert main([str(a) for a in argv]) == 0
    for seed in (4, 5):
        _fire(work / "shot2.xlsx", work / f"rec2_{seed}.csv", seed)
    return work


def _copy_archive(lot_of_one, tmp_path):
    import shutil

    shutil.copytree(lot_of_one / "arch", tmp_path / "arch", symlinks=True)
    return tmp_path / "arch"


def _chain(archive):
    """The lot's proposals' (version, shots' recordings, law) and its law as fill runs it."""
    from airgun_xl.archive.laws import list_laws, load_law
    from airgun_xl.archive.lots import proposals

    found = [(v, [Path(s["recording"]).name for s in r["shots"]], r["law"])
             for v, r in proposals(archive, "LOT")]
    return found, load_law(archive, "LOT")[0].source, [r["ref"] for r in list_laws(archive)]


def _held(tmp_path, argv, stage):
    """``airgun-xl argv`` in a child process held at ``stage``: (process, release)."""
    import subprocess
    import sys
    import time

    folder = tmp_path / "stages"
    folder.mkdir(exist_ok=True)
    hold, reached = folder / f"{stage}.hold", folder / f"{stage}.reached"
    hold.touch()
    proc = subprocess.Popen([sys.executable, "-m", "airgun_xl", *map(str, argv)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "AIRGUN_XL_STAGES": str(folder)})
    deadline = time.monotonic() + 300
    while not reached.exists():
        assert proc.poll() is None, proc.communicate()[1]
        assert time.monotonic() < deadline, f"{stage} not reached"
        time.sleep(0.002)  # a poll for the stage's file
    return proc, lambda: hold.unlink()



@pytest.mark.slow
def test_59_3_two_next_calls_at_once_keep_both_shots_or_refuse_one(lot_of_one, tmp_path,
                                                                     capsys):
    """The data loss: two next calls on one lot both exited 0 and the later proposal lacked
    the other's shot. Call A is held after its law is stored (it has read the chain), call B
    runs whole meanwhile; A is then refused in one line, exit 2, and takes back its law,
    workbook and verdict; the chain holds B's shot, and A run again holds both."""
    from airgun_xl.cli import main

    work = lot_of_one
    archive = _copy_archive(work, tmp_path)
    before, prior, laws = _chain(archive)
    a = _next_argv(work / "shot2.xlsx", work / "rec2_4.csv", archive, "-o", tmp_path / "a.xlsx")
    b = _next_argv(work / "shot2.xlsx", work / "rec2_5.csv", archive, "-o", tmp_path / "b.xlsx")
    proc, release = _held(tmp_path, a, "next-law-stored")
    assert main([str(x) for x in b]) == 0
    after_b = _chain(archive)
    release()
    _, err = proc.communicate(timeout=300)
    lines = err.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, err
    assert "another next stored the lot LOT's proposal LOT@2 while this one ran" in lines[0]
    assert not (tmp_path / "a.xlsx").exists()
    assert _chain(archive) == after_b  # A's law taken back: B's is the lot's
    assert after_b[0][-1][1] == ["rec1.csv", "rec2_5.csv"]
    capsys.readouterr()
    assert main([str(x) for x in a]) == 0
    chain, law, _ = _chain(archive)
    assert [c[1] for c in chain] == [["rec1.csv"], ["rec1.csv", "rec2_5.csv"],
                                     ["rec1.csv", "rec2_5.csv", "rec2_4.csv"]]
    assert law == chain[-1][2] and before == chain[:1] and prior == chain[0][2]


@pytest.mark.slow
@pytest.mark.parametrize("stage", ["next-law-stored", "publishing", "published",
                                   "next-verdict-stored", "next-proposal-stored"])
def test_59_4_a_sigkill_anywhere_in_next_leaves_the_chain_before_or_after(lot_of_one,
                                                                          tmp_path, stage):
    """SIGKILL at each of next's stages: the lot's chain (its proposals, the law fill and
    next take, the laws listed) is as before the call or as after it, never between; the
    law of a killed call is never the next call's prior (the orphan law found)."""
    import signal

    from support import at_stage

    from airgun_xl.cli import main

    work = lot_of_one
    archive = _copy_archive(work, tmp_path)
    before = _chain(archive)
    argv = _next_argv(work / "shot2.xlsx", work / "rec2_4.csv", archive, "-o",
                      tmp_path / "a.xlsx")
    code, err, reached = at_stage(tmp_path, argv, stage, signal.SIGKILL)
    assert reached and code == -signal.SIGKILL, err
    after = _chain(archive)
    if stage == "next-proposal-stored":  # the commit point passed: finished
        assert after[0][-1][1] == ["rec1.csv", "rec2_4.csv"] and after[1] == after[0][-1][2]
        assert after[1] in after[2]
        return
    assert after == before
    assert main([str(x) for x in argv + ["--force"]]) == 0  # the call again: whole
    chain, law, laws = _chain(archive)
    assert [c[1] for c in chain] == [["rec1.csv"], ["rec1.csv", "rec2_4.csv"]]
    assert law == chain[-1][2] and law in laws


@pytest.mark.parametrize("kind", ["FIFO", "folder"])
def test_59_5_a_fifo_or_folder_as_the_next_version_is_named_before_any_work(lot_of_one,
                                                                            tmp_path, capsys,
                                                                            kind):
    """It was blamed on "fewer writers" after the whole computation: now the lot's chain is
    read with it, and it is named, in one line, before the Monte Carlo."""
    work = lot_of_one
    archive = _copy_archive(work, tmp_path)
    planted = archive / ".lots" / "LOT" / "v0002.json"
    os.mkfifo(planted) if kind == "FIFO" else planted.mkdir()
    argv = _next_argv(work / "shot2.xlsx", work / "rec2_4.csv", archive, "-o",
                      tmp_path / "a.xlsx")
    refused(capsys, argv, archive, tmp_path, naming=("v0002.json", "not a regular file"))


# -- 59.6: bounds ----------------------------------------------------------------------------

def _pulse_g(n=2000):
    """A half-sine of 1,000 g amid rest: a recording any command can judge."""
    g = np.zeros(n)
    g[n // 4: n // 2] = 1000.0 * np.sin(np.linspace(0.0, np.pi, n // 4))
    return g


def _with_step(kind, folder, step):
    """A recording of :func:`_pulse_g` at ``step`` [s] in format ``kind``."""
    g = _pulse_g()
    if kind == "csv":
        path = folder / "r.csv"
        path.write_text("time [s],acceleration [g]\n" + "".join(
            f"{float(k * step)!r},{float(v)!r}\n" for k, v in enumerate(g)))
        return path
    if kind == "mat":
        from scipy.io import savemat

        savemat(folder / "r.mat", {"fs": 1.0 / step, "accel": g, "accel_unit": "g"})
        return folder / "r.mat"
    if kind == "tdms":
        nptdms = pytest.importorskip("nptdms")
        with nptdms.TdmsWriter(str(folder / "r.tdms")) as writer:
            writer.write_segment([nptdms.ChannelObject(
                "g", "accel", g, properties={"wf_increment": step, "unit_string": "g"})])
        return folder / "r.tdms"
    from test_recording_formats import _write_mme

    test = _write_mme(folder / "mme", np.arange(len(g)) * step, g)
    return test.parent / "Channel" / "TEST.002"


@pytest.mark.parametrize("kind", ["csv", "mat", "tdms", "mme"])
@pytest.mark.parametrize("step", [1e-300, 1e-12, 10.0])
def test_59_6_a_recordings_sample_step_is_bounded_in_every_format(tmp_path, capsys, kind,
                                                                   step):
    """MATLAB fs 1e308, TDMS wf_increment 1e-300, MME's interval 1e-300 gave tracebacks, and
    1e12 Hz 1.1 GB before one line: each format is refused alike, naming the step."""
    path = _with_step(kind, tmp_path, step)
    refused(capsys, ["accept", TEMPLATE, path, "--peak", "1000g:10%", "-o",
                     tmp_path / "v.xlsx"], tmp_path,
            naming=("its sample step is", "expected a step of 1e-09 to 1 s"))


def test_59_6_a_terahertz_recording_is_refused_before_its_memory_is_spent(tmp_path):
    """In a child: the refusal of 1e12 Hz costs what reading the file does (it cost 3 GB)."""
    from support import run_child

    path = _with_step("mat", tmp_path, 1e-12)
    code, err, rss = run_child(tmp_path, ["accept", TEMPLATE, path, "--peak", "1000g:10%",
                                          "-o", tmp_path / "v.xlsx"])
    assert code == 2 and "its sample step is 1e-12 s" in err, err
    assert rss is None or rss < 300 * 2**20  # the import of numpy and the readers: ~130 MB


def test_59_6_one_gigahertz_is_still_read(tmp_path):
    """The bound's edge: a recorder at 1 GHz is read, its step exact."""
    trace = read_trace(_with_step("mat", tmp_path, 1e-9))
    assert trace.dt == pytest.approx(1e-9, rel=1e-12)


@pytest.mark.parametrize("option", [["--shots", "10000000"], ["--shots", "1000000000"],
                                    ["--seed", "-1"], ["--seed", str(2**128)]])
def test_59_6_next_shots_and_seed_are_bounded_before_any_work(tmp_path, capsys, option):
    recording = TEMPLATE.with_name("shot_a_recording.csv")
    argv = ["next", TEMPLATE, recording, "--archive", tmp_path / "arch", "--lot", "LOT",
            "--new-lot", "--sd", "A28=1.5%", "--peak", "12kG:10%", "-o", tmp_path / "n.xlsx",
            *option]
    said = refused(capsys, argv, tmp_path, naming=(f"{option[0]}: found {option[1]}",))
    assert ("100 to 1,000,000" if option[0] == "--shots" else "2**128 - 1") in said


# -- 59.7: tracebacks ------------------------------------------------------------------------

def test_59_7_a_recording_of_subnormal_numbers_is_one_line(tmp_path, capsys):
    """compare-measured died with ZeroDivisionError (math domain error before) on it."""
    g = np.full(1000, 5e-324)
    g[400:600] = 1e-320
    path = tmp_path / "r.csv"
    path.write_text("time [s],acceleration [g]\n" + "".join(
        f"{float(k * 1e-5)!r},{float(v)!r}\n" for k, v in enumerate(g)))
    for command in (["compare-measured", TEMPLATE, path, "-o", tmp_path / "c.xlsx"],
                    ["accept", TEMPLATE, path, "--peak", "9kG:10%", "-o", tmp_path / "v.xlsx"]):
        refused(capsys, command, tmp_path,
                naming=("the recording is flat (its largest acceleration is",
                        "expected a pulse of at least 1e-06 kG"))


API_PATHS = {
    "load path": lambda bad: airgun_xl_api().load(bad),
    "fill shot": lambda bad: airgun_xl_api().fill(bad),
    "fill output": lambda bad: airgun_xl_api().fill(TEMPLATE, output=bad),
    "accept recording": lambda bad: airgun_xl_api().accept(TEMPLATE, bad, peak="12kG:10%"),
    "accept archive": lambda bad: airgun_xl_api().accept(
        TEMPLATE, TEMPLATE.with_name("shot_a_recording.csv"), peak="12kG:10%", sign=-1,
        archive=bad),
    "calibrate files": lambda bad: airgun_xl_api().calibrate(TEMPLATE, bad),
    "campaign shots": lambda bad: airgun_xl_api().campaign([TEMPLATE, bad]),
    "history archive": lambda bad: airgun_xl_api().history(archive=bad),
    "recording path": lambda bad: airgun_xl_api().recording(bad),
    "template output": lambda bad: airgun_xl_api().template(bad),
    "diff new": lambda bad: airgun_xl_api().diff(TEMPLATE, bad),
    "next_shot recording": lambda bad: airgun_xl_api().next_shot(
        TEMPLATE, bad, archive="arch", lot="L", new_lot=True, sd=["A28=1.5%"], peak="9kG:10%"),
}


def airgun_xl_api():
    import airgun_xl

    return airgun_xl


#: The arguments whose None is their default (no output named, $AIRGUN_XL_ARCHIVE).
OPTIONAL = {"fill output", "accept archive", "history archive"}


@pytest.mark.parametrize(("call", "bad"), [
    (call, bad) for call in sorted(API_PATHS) for bad in (3, 2.5, None, b"\x00", object())
    if not (bad is None and call in OPTIONAL)])
def test_59_7_the_apis_path_arguments_are_checked_and_named(tmp_path, monkeypatch, call,
                                                            bad):
    """A raw TypeError came out of each; now one OptionError naming the argument, and
    nothing written."""
    from airgun_xl.errors import OptionError

    monkeypatch.chdir(tmp_path)
    name = call.split()[-1]
    with pytest.raises(OptionError, match=rf"^{name}: found .*, expected a file's path"):
        API_PATHS[call](bad)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("port", ["x", 2.5, None])
def test_59_7_the_apis_port_is_checked_and_named(tmp_path, port):
    import airgun_xl
    from airgun_xl.errors import OptionError

    with pytest.raises(OptionError, match=r"^port: found"):
        airgun_xl.serve(tmp_path, port=port)


def test_59_8_a_tdms_step_stored_as_text_is_not_read_as_a_number(tmp_path, capsys):
    nptdms = pytest.importorskip("nptdms")
    path = tmp_path / "r.tdms"
    with nptdms.TdmsWriter(str(path)) as writer:
        writer.write_segment([nptdms.ChannelObject(
            "g", "accel", _pulse_g(), properties={"wf_increment": "1e-05",
                                                 "unit_string": "g"})])
    refused(capsys, ["accept", TEMPLATE, path, "--peak", "1000g:10%", "-o",
                     tmp_path / "v.xlsx"], tmp_path,
            naming=("wf_increment stored as str, not a number",))


# -- 59.9 to 59.12: the lot's records read back ----------------------------------------------

def _edit(path, change):
    import json

    record = json.loads(path.read_text())
    change(record)
    path.write_text(json.dumps(record))


def test_59_9_a_shot_listed_eight_times_in_a_proposal_is_refused(lot_of_one, tmp_path, capsys):
    """It counted as 8 shots: the gun's scatter "estimated" from one, P(PASS) 1.0000."""
    work = lot_of_one
    archive = _copy_archive(work, tmp_path)
    _edit(archive / ".lots" / "LOT" / "v0001.json", lambda r: r.update(shots=r["shots"] * 8))
    argv = _next_argv(work / "shot2.xlsx", work / "rec2_4.csv", archive, "-o",
                      tmp_path / "a.xlsx")
    refused(capsys, argv, archive, tmp_path, naming=("v0001.json: lists the shot", "twice"))


@pytest.mark.parametrize("factor", [0.0, -1.0, 1e-300, 10.0])
def test_59_10_a_lots_law_of_no_honeycombs_strength_is_refused(lot_of_one, tmp_path, capsys,
                                                                factor):
    """A law of zero, negative or 1e-300 strength was taken as the prior and stored again."""
    work = lot_of_one
    archive = _copy_archive(work, tmp_path)
    _edit(archive / ".laws" / "LOT" / "v0001.json",
          lambda r: r.update(coefficients=[c * factor for c in r["coefficients"]]))
    argv = _next_argv(work / "shot2.xlsx", work / "rec2_4.csv", archive, "-o",
                      tmp_path / "a.xlsx")
    refused(capsys, argv, archive, tmp_path,
            naming=("LOT@1: the lot's law is", "times the report's law over its range, "
                    "expected 0.25 to 4 times"))


@pytest.mark.slow
@pytest.mark.parametrize("recording", ["noise", "ten times"])
def test_59_11_a_recording_the_model_does_not_describe_never_moves_the_law(lot_of_one,
                                                                          tmp_path, capsys,
                                                                          recording):
    """Pure noise, or the pulse ten times too large, was fitted into the lot's law (the next
    A28 moved from 237.7 to 206.0 m/s) though the tool said the model does not describe it:
    now refused in one line naming the recording, the lot unchanged."""
    from conftest import write_trace_csv

    from airgun_xl.readers.recording import Trace

    work = lot_of_one
    archive = _copy_archive(work, tmp_path)
    fired = read_trace(work / "rec2_4.csv")
    if recording == "noise":
        accel = np.abs(np.random.default_rng(59).normal(0.0, 0.5, len(fired.time)))
    else:
        accel = fired.accel_kg * 10.0
    path = write_trace_csv(tmp_path / "bad.csv",
                           Trace(fired.time, accel, fired.dt, "bad", ("s", "kG")))
    argv = _next_argv(work / "shot2.xlsx", path, archive, "-o", tmp_path / "a.xlsx")
    said = refused(capsys, argv, archive, tmp_path,
                   naming=("bad.csv: the lot's law fitted to", "the lot's law is not updated"))
    assert ("RMS of its peak" in said) or ("times the report's law" in said)


def _gun_record(root, lot, gun, shots, launch):
    from airgun_xl.archive.lots import store_proposal

    return store_proposal(root, lot, {"lot": lot, "shot": "s.xlsx", "verdict": "PASS",
                                      "law": f"{lot}@1", "setting_A28": 240.0, "p_pass": 0.9,
                                      "interval": [0.85, 0.95], "next_sha256": "0" * 64,
                                      "gun_name": gun, "shots": shots, "launch": launch})


def _shot(k):
    return {"shot": f"s{k}.xlsx", "recording": f"r{k}.csv", "shot_sha256": f"{k:064x}",
            "recording_sha256": f"{k + 100:064x}"}


def _launch(shot, speed=240.0):
    return {"shot_sha256": shot["shot_sha256"], "recording_sha256": shot["recording_sha256"],
            "speed_m_s": speed, "factor": 1.0, "error": 0.01}


def test_59_12_forged_launch_entries_of_another_lot_are_never_counted(tmp_path):
    """Launch entries that are not one for each of the record's shots (eight forged for one
    shot, or one shot's twice) leave the lot out of the gun's scatter, named."""
    from airgun_xl.archive import Archive
    from airgun_xl.archive.lots import gun_launches
    from airgun_xl.errors import ArchiveError

    root = tmp_path / "arch"
    Archive(root, create=True)
    one = _shot(1)
    _gun_record(root, "FORGED", "GUN", [one], [_launch(one, 230.0 + k) for k in range(8)])
    with pytest.raises(ArchiveError, match="holds 8 launch velocities for its 1 shots"):
        gun_launches(root, "FORGED", "GUN")
    _gun_record(root, "TWICE", "GUN", [one, one], [_launch(one), _launch(one)])
    with pytest.raises(ArchiveError, match="twice, expected each shot once"):
        gun_launches(root, "TWICE", "GUN")
    two = [_shot(2), _shot(3)]
    _gun_record(root, "HONEST", "GUN", two, [_launch(s) for s in two])
    assert [e["shot_sha256"] for e in gun_launches(root, "HONEST", "GUN")] == \
        [s["shot_sha256"] for s in two]


def test_59_12_a_lot_whose_latest_shot_another_gun_fired_is_never_read(tmp_path):
    from airgun_xl.archive import Archive
    from airgun_xl.archive.lots import gun_launches

    root = tmp_path / "arch"
    Archive(root, create=True)
    two = [_shot(2), _shot(3)]
    _gun_record(root, "MOVED", "GUN", two, [_launch(s) for s in two])
    _gun_record(root, "MOVED", "OTHER", two, [_launch(s) for s in two])
    assert gun_launches(root, "MOVED", "GUN") == []
    assert len(gun_launches(root, "MOVED", "OTHER")) == 2


# -- 59.13 to 59.16: the archive's view and listing ------------------------------------------

@pytest.fixture
def archive_of_two(tmp_path):
    """An SQLite archive of shot_a@1 and shot_a@2."""
    from airgun_xl.cli import main

    root = tmp_path / "archive"
    for _ in range(2):
        assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--force",
                     "--only", "summary", "--archive", str(root)]) == 0
    return root


@pytest.mark.parametrize("shot, version, why", [
    ("other", 1, "row #9: it says other@1, but its folder shot_a/v0001 is shot_a@1's"),
    ("shot_a", 3, "row #9: it says shot_a@3, but its folder shot_a/v0001 is shot_a@1's"),
])
def test_59_13_history_flags_a_row_that_names_another_entrys_folder(archive_of_two, capsys,
                                                                    shot, version, why):
    """show and verify refused such a row; history listed it as the entry it says."""
    import sqlite3

    from airgun_xl.cli import main

    conn = sqlite3.connect(archive_of_two / "index.sqlite", isolation_level=None)
    columns = [r[1] for r in conn.execute("PRAGMA table_info(entries)")]
    kept = [c for c in columns if c not in ("id", "shot", "version")]
    conn.execute(f"INSERT INTO entries (id, shot, version, {', '.join(kept)}) SELECT 9, ?, ?, "
                 f"{', '.join(kept)} FROM entries WHERE id = 1", (shot, version))
    conn.close()
    capsys.readouterr()
    assert main(["history", "--archive", str(archive_of_two)]) == 0
    out = capsys.readouterr().out
    assert f"unreadable: {why}" in out, out
    assert out.count("unreadable:") == 1


def test_59_14_the_views_peak_band_converts_g_by_the_macros_kg(tmp_path):
    """The view drew a band given in g at 1/1000 kG a g: 0.068 % low."""
    from airgun_xl.units import KG_MS2, G
    from airgun_xl.web.server import _peak_band

    band = _peak_band(None, [{"version": 1, "criteria": [
        {"name": "peak", "unit": "g", "low": 9000.0, "high": 11000.0}]}])
    # the chart keeps 6 significant digits: within 5e-6 of the exact factor, where 1/1000
    # would be 6.8e-4 off
    assert band["low"] == pytest.approx(9000.0 * G / KG_MS2, rel=5e-6)
    assert band["high"] == pytest.approx(11000.0 * G / KG_MS2, rel=5e-6)


@pytest.mark.parametrize("host, loopback", [("127.0.0.1", True), ("127.0.0.2", True),
                                            ("127.255.0.9", True), ("::1", True),
                                            ("[::1]", True), ("localhost", True),
                                            ("0.0.0.0", False), ("10.0.0.1", False),
                                            ("lab-pc", False)])
def test_59_15_serve_knows_the_whole_loopback_range(host, loopback):
    from airgun_xl.web.server import is_loopback

    assert is_loopback(host) is loopback


def test_59_15_serve_host_warns_only_once_it_listens(archive_of_two, capsys):
    """A port in use with --host 0.0.0.0 gave two lines (the warning, then the refusal)."""
    import socket

    pytest.importorskip("starlette")
    pytest.importorskip("uvicorn")

    busy = socket.socket()
    busy.bind(("0.0.0.0", 0))
    busy.listen()
    try:
        refused(capsys, ["serve", "--archive", archive_of_two, "--host", "0.0.0.0", "--port",
                         busy.getsockname()[1]], archive_of_two, naming=("--port",))
    finally:
        busy.close()


@pytest.mark.slow
def test_59_16_a_damaged_index_while_serve_runs_is_answered_with_the_headers(archive_of_two):
    """serve answered 500 without its security headers when the index was damaged while it
    ran: now every answer carries them."""
    pytest.importorskip("starlette")
    from serve_helpers import get, serving

    with serving(archive_of_two) as url:
        assert get(f"{url}/")[0] == 200
        (archive_of_two / "index.sqlite").write_bytes(b"not a database" * 100)
        status, headers, _ = get(f"{url}/")
        lowered = {k.lower(): v for k, v in headers.items()}
        assert status >= 400
        assert lowered["content-security-policy"].startswith("default-src 'self';")
        assert lowered["x-content-type-options"] == "nosniff"
