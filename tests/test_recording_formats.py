"""Issue 47: recordings in the formats labs export, each fixture written by the format's own
writer (scipy's savemat for MATLAB v5, h5py for v7.3 with MATLAB's header and classes), hold
the pulse of a reference CSV: accept, compare-measured and calibrate give the same verdicts
and figures from each; the channels are listed, chosen by name or number; a file that lies is
one line, exit 2, nothing written."""
import gc
import io
import json
import os
import warnings

import numpy as np
import pytest
from conftest import TEMPLATE, write_trace_csv
from scipy.io import savemat

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.crush_law import LEGACY_LAW
from airgun_xl.studies.calibrate import synthetic_measurement
from airgun_xl.units import G

#: kG per g: the recorder's g is standard gravity, the macro's kG 9,800 m/s^2.
KG_PER_G = G / 9800.0

#: A specification the pulse passes on peak and duration (tests/test_pdf_report.py's).
SPEC = {"peak": "9.3kG:5%", "duration": "4.74ms:15%"}


@pytest.fixture(scope="module")
def pulse(tmp_path_factory):
    """Shot A fired on a lot 10 % stronger, recorded at 51.2 kHz with 1 % noise, as a CSV
    in kG (the reference) and as the same samples in each format."""
    folder = tmp_path_factory.mktemp("formats")
    p = airgun_xl.load(TEMPLATE).params.replace(crush_law=LEGACY_LAW.scaled(1.10))
    trace = synthetic_measurement(p, dt=1 / 51_200, seed=3)
    files = {"csv": write_trace_csv(folder / "ref.csv", trace)}
    # v5, compressed, as a recorder's export: a time vector in ms, the channel in kG beside a
    # second one, units as text variables
    savemat(folder / "v5.mat", {"time": trace.time * 1e3, "time_unit": "ms",
                                "accel": trace.accel_kg, "accel_unit": "kG",
                                "strain": np.linspace(0, 1, len(trace.time)),
                                "note": "shot 1"},
            do_compression=True, oned_as="column")
    # v5 without a time vector: the rate and the start, the channel in g
    savemat(folder / "fs.mat", {"fs": 51_200.0, "t0": float(trace.time[0]),
                                "accel": trace.accel_kg / KG_PER_G, "accel_unit": "g"})
    files.update(v5=folder / "v5.mat", fs=folder / "fs.mat")
    if _pyuff() is not None:
        t, g = trace.time, trace.accel_kg / KG_PER_G
        for binary, name in ((0, "ascii.uff"), (1, "binary.uff")):
            files[name.split(".")[0]] = _write_uff58(folder / name, binary, [
                ("temperature", np.full(len(t), 21.0), "C", t),
                ("accel", g, "g", t)])
        # an even abscissa keeps its start and increment as E13.5 (6 significant digits):
        # the same samples on that time base, as a CSV, are what the UFF files hold
        stored = float(f"{t[0]:.5E}") + np.arange(len(t)) * float(f"{t[1] - t[0]:.5E}")
        files["uff_csv"] = folder / "uff_ref.csv"
        files["uff_csv"].write_text("time [s],acceleration [g]\n" + "".join(
            f"{x!r},{y!r}\n" for x, y in zip(stored.tolist(), g.tolist(), strict=True)))
    test = _write_mme(folder / "mme", trace.time, trace.accel_kg / KG_PER_G)
    files["mme"] = test.parent / "Channel" / "TEST.002"
    if _asammdf() is not None:
        files["mdf"] = _write_mdf(folder / "shot.mf4", trace.time, trace.accel_kg / KG_PER_G)
    if _idelib() is not None:
        files["ide"], files["ide_csv"] = _write_ide(folder / "shot.ide", folder / "ide_ref.csv",
                                                    trace.accel_kg / KG_PER_G)
    if _h5py() is not None:
        files["v73"] = _write_v73(folder / "v73.mat", {"time": trace.time, "time_unit": "s",
                                                       "accel": trace.accel_kg / KG_PER_G,
                                                       "accel_unit": "g"})
    return folder, trace, files


def _h5py():
    try:
        import h5py
    except ImportError:
        return None
    return h5py


def _asammdf():
    try:
        with warnings.catch_warnings():  # asammdf 8.1's canmatrix import is deprecated
            warnings.simplefilter("ignore", DeprecationWarning)
            import asammdf
    except ImportError:
        return None
    return asammdf


def _write_mdf(path, t, g):
    """An MDF 4.10 file by asammdf's own writer: a slow group (a temperature at 1 kHz) first,
    then the pulse in g on its own time base, as a recorder of mixed rates writes them."""
    from asammdf import MDF, Signal

    mdf = MDF(version="4.10")
    slow = np.arange(50) / 1000.0
    mdf.append([Signal(np.full(50, 21.0), slow, name="temperature", unit="degC")],
               comment="slow")
    mdf.append([Signal(np.asarray(g, dtype=float), np.asarray(t, dtype=float), name="accel",
                       unit="g")], comment="fast")
    mdf.save(path, overwrite=True)
    mdf.close()
    return path


def _idelib():
    try:
        import idelib
    except ImportError:
        return None
    return idelib


#: The IDE fixture's calibration: g = IDE_GAIN * counts + IDE_OFFSET (16-bit counts: the pulse
#: peaks near 9,500 g, 19,000 counts).
IDE_GAIN, IDE_OFFSET = 0.5, 1.5


def _write_ide(path, csv, g, rate=51_200, per_block=100, properties=True):
    """An enDAQ IDE file by ebmlite's writer on idelib's own schema: a temperature channel,
    then the pulse as 16-bit counts of an accelerometer's subchannel ``X`` with a
    calibration polynomial (gain and offset) to g, in blocks whose time codes count samples
    (TimeCodeScale 1/rate); and ``csv``, the same samples as the file defines them (time k /
    rate from its start, g = gain x counts + offset), worked out here, not by idelib."""
    from ebmlite import loadSchema

    counts = np.round((np.asarray(g) - IDE_OFFSET) / IDE_GAIN).astype("<i2")
    accel = [{"ChannelDataBlock": {
        "ChannelIDRef": 8, "StartTimeCodeAbsMod": k,
        "EndTimeCodeAbsMod": min(k + per_block, len(counts)) - 1,
        "ChannelDataPayload": counts[k:k + per_block].tobytes()}}
        for k in range(0, len(counts), per_block)]
    temperature = [{"ChannelDataBlock": {
        "ChannelIDRef": 36, "StartTimeCodeAbsMod": 0, "EndTimeCodeAbsMod": 9,
        "ChannelDataPayload": np.full(10, 21.0, dtype="<f4").tobytes()}}]

    def channel(number, name, fmt, sub, unit, calibration=None):
        described = {"SubChannelID": 0, "SubChannelName": sub, "SubChannelUnits": unit,
                     "SubChannelSensorRef": 0}
        if calibration is not None:
            described["SubChannelCalibrationIDRef"] = calibration
        return {"ChannelID": number, "ChannelName": name, "ChannelFormat": fmt,
                "TimeCodeScale": f"1/{rate}", "TimeCodeModulus": 2**32,
                "SampleRate": str(rate), "SubChannel": [described]}

    head = [{"RecordingProperties": {
        "SensorList": {"Sensor": [{"SensorID": 0, "SensorName": "bird recorder"}]},
        "ChannelList": {"Channel": [channel(36, "Temperature", "<f", "T", "degC"),
                                    channel(8, "Acceleration", "<h", "X", "g", 1)]}}},
        {"CalibrationList": {"UnivariatePolynomial": [
            {"CalID": 1, "CalReferenceValue": 0.0, "PolynomialCoef": [IDE_GAIN, IDE_OFFSET]}]}}]
    path.write_bytes(loadSchema("mide_ide.xml").encodes(
        (head if properties else []) + temperature + accel, headers=True))
    values = IDE_GAIN * counts.astype(float) + IDE_OFFSET
    csv.write_text("time [s],acceleration [g]\n" + "".join(
        f"{k / rate!r},{v!r}\n" for k, v in enumerate(values.tolist())))
    return path, csv


def _pyuff():
    try:
        import pyuff
    except ImportError:
        return None
    return pyuff


def _write_uff58(path, binary, channels):
    """Time responses written by pyuff's own writer (dataset 58, or 58b when ``binary``):
    each (name, values, unit, time [s]) on an even abscissa."""
    pyuff = _pyuff()
    uff = pyuff.UFF(str(path))
    for node, (name, values, unit, t) in enumerate(channels, start=1):
        dataset = pyuff.prepare_58(
            binary=binary, id1=name, id2="airgun-xl test", id3="NONE", id4="NONE", id5="NONE",
            func_type=1, ver_num=0, load_case_id=0, rsp_ent_name="BIRD", rsp_node=node,
            rsp_dir=3, ref_ent_name="NONE", ref_node=0, ref_dir=0, ord_data_type=4,
            num_pts=len(values), abscissa_spacing=1, abscissa_min=float(t[0]),
            abscissa_inc=float(t[1] - t[0]), z_axis_value=0.0, abscissa_spec_data_type=17,
            abscissa_len_unit_exp=0, abscissa_force_unit_exp=0, abscissa_temp_unit_exp=0,
            abscissa_axis_units_lab="s", ordinate_spec_data_type=12,
            ordinate_len_unit_exp=1, ordinate_force_unit_exp=0, ordinate_temp_unit_exp=0,
            ordinate_axis_units_lab=unit, orddenom_spec_data_type=0,
            orddenom_len_unit_exp=0, orddenom_force_unit_exp=0, orddenom_temp_unit_exp=0,
            orddenom_axis_units_lab="NONE", z_axis_spec_data_type=0, z_axis_len_unit_exp=0,
            z_axis_force_unit_exp=0, z_axis_temp_unit_exp=0, z_axis_axis_units_lab="NONE",
            data=np.asarray(values, dtype=float), x=np.asarray(t, dtype=float))
        with warnings.catch_warnings():  # pyuff 2.5.0's writer leaves its file to the GC
            warnings.simplefilter("ignore", ResourceWarning)
            uff.write_sets(dataset, mode="add")
            gc.collect()
    return path


def _write_v73(path, variables):
    """A MATLAB v7.3 file as MATLAB writes one: a 512-byte user block holding the v7.3 text
    header, then HDF5 datasets with their MATLAB_class (a column vector stored 1 x n, text as
    UTF-16 code units)."""
    h5py = _h5py()
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            if isinstance(value, str):
                data = np.array([[ord(c) for c in value]], dtype=np.uint16).T
                ds = f.create_dataset(name, data=data)
                ds.attrs["MATLAB_class"] = np.bytes_("char")
                ds.attrs["MATLAB_int_decode"] = np.int32(2)
            else:
                ds = f.create_dataset(name, data=np.asarray(value, dtype=float)[None, :])
                ds.attrs["MATLAB_class"] = np.bytes_("double")
    header = (b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Fri Nov 27 00:00:00 2026 "
              b"HDF5 schema 1.00 .").ljust(116) + bytes(8) + b"\x00\x02IM"
    with open(path, "r+b") as fh:
        fh.write(header.ljust(512, b"\x00"))
    return path


def test_scipy_reads_our_v73_header_as_v73(pulse):
    """The v7.3 fixture is what MATLAB writes, by scipy's own reading of its header."""
    from scipy.io.matlab import matfile_version

    if "v73" not in pulse[2]:
        pytest.skip("needs h5py")
    with open(pulse[2]["v73"], "rb") as fh:
        assert matfile_version(fh) == (2, 0)


@pytest.mark.parametrize("kind", ["v5", "fs", "v73", "ascii", "binary", "mdf", "ide"])
def test_accept_gives_the_csvs_verdict_and_figures(pulse, kind, tmp_path):
    """Every criterion's value from the file equals the CSV's within 1e-12 relative: the file
    holds the samples in g or its time in ms, or as fs and t0, and a product's rounding is
    in the last bits (the same on one numpy version, a few ulps apart on another, measured
    on the lowest versions); for UFF's ASCII dataset 58, within its stored precision
    (4E20.12: 13 significant digits, so 1e-11 relative). A UFF
    file's time base is its header's start and increment, stored as E13.5: its reference is
    the CSV of the same samples on that time base. Its second time response is chosen by its
    name. An IDE file's reference is the CSV of the samples it defines (its 16-bit counts
    through its calibration polynomial, its time codes' times), its channel chosen by name."""
    folder, trace, files = pulse
    if kind not in files:
        pytest.skip("needs h5py, pyuff, asammdf or idelib")
    uff = kind in ("ascii", "binary")
    channel = ({"channel": "accel"} if uff or kind == "mdf" else
               {"channel": "Acceleration/X"} if kind == "ide" else {})
    reference = airgun_xl.accept(TEMPLATE, files["uff_csv" if uff else "ide_csv" if kind == "ide"
                                                 else "csv"], **SPEC)
    found = airgun_xl.accept(TEMPLATE, files[kind], **SPEC, **channel)
    assert found.verdict.word == reference.verdict.word == "PASS"
    for mine, theirs in zip(found.verdict.criteria, reference.verdict.criteria, strict=True):
        assert (mine.name, mine.unit, mine.passed) == (theirs.name, theirs.unit, theirs.passed)
        rel = 1e-11 if kind == "ascii" else 1e-12
        assert mine.value == pytest.approx(theirs.value, rel=rel), mine.name


#: Each format's file, its reference CSV (the same samples) and its channel option.
SOURCES = {"v5": ("csv", {}), "mdf": ("csv", {"channel": "accel"}),
           "binary": ("uff_csv", {"channel": "accel"}), "mme": ("csv", {}),
           "ide": ("ide_csv", {"channel": "Acceleration/X"})}


@pytest.mark.parametrize("kind", list(SOURCES))
def test_compare_measured_and_calibrate_give_the_csvs_figures(pulse, kind):
    """compare-measured's figures and calibrate's fit from each format equal the reference
    CSV's: the figures within a rounding of the time (v5 holds it in ms), the fit to a
    thousandth of its standard error (the optimiser stops on a tolerance)."""
    folder, trace, files = pulse
    if kind not in files:
        pytest.skip("needs pyuff, asammdf or idelib")
    reference, channel = SOURCES[kind]
    ref = airgun_xl.compare_measured(TEMPLATE, files[reference]).comparison
    mine = airgun_xl.compare_measured(TEMPLATE, files[kind], **channel).comparison
    for field in ("peak_kg", "time_of_peak", "pulse_duration", "delta_v"):
        assert getattr(mine.measured, field) == pytest.approx(getattr(ref.measured, field),
                                                              rel=1e-12), field
    assert mine.correlation == pytest.approx(ref.correlation, rel=1e-12)
    calibrations = [airgun_xl.calibrate(TEMPLATE, files[reference], fit="scale").calibration,
                    airgun_xl.calibrate(TEMPLATE, files[kind], fit="scale",
                                        **channel).calibration]
    fitted = [c.fitted for c in calibrations]
    errors = calibrations[0].errors
    assert fitted[0].keys() == fitted[1].keys() and fitted[0]
    for key in fitted[0]:
        assert abs(fitted[1][key] - fitted[0][key]) < 1e-3 * errors[key], key


def test_the_channels_are_listed_and_chosen_by_name_or_number(pulse, capsys):
    """``airgun-xl recording FILE`` lists each channel's name, unit, rate (the measured one,
    from the time vector), samples and start; --channel takes a name or a number."""
    folder, trace, files = pulse
    assert main(["recording", str(files["v5"]), "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)["channels"]
    assert [c["name"] for c in listed] == ["accel", "strain"]
    accel = listed[0]
    assert accel["unit"] == "kG" and accel["samples"] == len(trace.time)
    assert accel["rate_hz"] == pytest.approx(51_200, rel=1e-9)
    assert accel["start_s"] == pytest.approx(trace.time[0], abs=1e-15)
    by_name = airgun_xl.compare_measured(TEMPLATE, files["v5"], channel="accel")
    by_number = airgun_xl.compare_measured(TEMPLATE, files["v5"], channel="1")
    assert by_name.comparison.measured == by_number.comparison.measured
    assert main(["recording", str(files["csv"])]) == 0
    text = capsys.readouterr().out
    assert "acceleration [kG]" in text and "51,200" in text


@pytest.mark.parametrize("variables, message", [
    ({"accel": np.ones(100)}, "channel 'accel' has no time base (a vector 'time' or 't' of "
                              "its 100 samples, or a scalar fs or dt)"),
    ({"accel": np.ones(100), "fs": -5.0}, "fs is -5.0, expected a positive rate [Hz]"),
    ({"note": "text only"}, "holds no numeric vector"),
    ({"accel": np.ones(100) + 1j, "fs": 1e4}, "holds complex128 values, expected real"),
    ({"accel": np.r_[np.ones(50), np.nan, np.ones(49)], "fs": 1e4},
     "channel 'accel' sample 51 is nan, expected finite numbers"),
])
def test_a_mat_file_that_cannot_be_a_recording_is_one_line(tmp_path, capsys, variables,
                                                           message):
    path = tmp_path / "r.mat"
    savemat(path, variables)
    out = tmp_path / "c.xlsx"
    assert main(["compare-measured", str(TEMPLATE), str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.mat"]


def test_a_mat_file_cut_short_or_lying_about_its_length_is_one_line(pulse, tmp_path, capsys):
    """A file cut at each tenth of its length, and a variable whose header declares 2 x 10^9
    samples (16 GB), are one line each (refused before any allocation of that size)."""
    folder, trace, files = pulse
    data = files["fs"].read_bytes()
    for cut in range(1, 10):
        path = tmp_path / f"cut{cut}.mat"
        path.write_bytes(data[: len(data) * cut // 10])
        assert main(["accept", str(TEMPLATE), str(path), "--peak", "9kG:10%"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(path) in err, err
    path = tmp_path / "lying.mat"
    for compressed in (True, False):  # the dimensions inside a zlib stream, or in the open
        path.write_bytes(_declaring(1, 2_000_000_000, compressed))  # int32 dims: 16 GB
        assert main(["accept", str(TEMPLATE), str(path), "--peak", "9kG:10%"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "holds 2,000,000,000 samples, expected at most" in err


def _declaring(rows, columns, compressed=True):
    """A v5 file by savemat whose 1000-sample ``accel`` declares ``rows`` x ``columns``:
    in a compressed file the dimensions are inside each variable's zlib stream, so the
    stream is inflated, patched and deflated again (its byte count rewritten)."""
    import zlib

    buffer = io.BytesIO()
    savemat(buffer, {"fs": 1e4, "accel": np.ones(1000)}, do_compression=compressed)
    data = buffer.getvalue()
    old = np.array([1, 1000], dtype="<i4").tobytes()  # savemat writes a vector as 1 x n
    new = np.array([rows, columns], dtype="<i4").tobytes()
    if not compressed:
        assert data.count(old) == 1
        return data.replace(old, new)
    out, at = bytearray(data[:128]), 128
    while at < len(data):
        kind, size = np.frombuffer(data[at:at + 8], dtype="<i4")
        body = data[at + 8:at + 8 + size]
        if kind == 15:  # miCOMPRESSED
            inner = zlib.decompress(body)
            if old in inner:
                body = zlib.compress(inner.replace(old, new))
        out += np.array([kind, len(body)], dtype="<i4").tobytes() + body
        at += 8 + size
    return bytes(out)


def test_a_wrong_channel_lists_the_files_channels(pulse, capsys):
    folder, trace, files = pulse
    assert main(["accept", str(TEMPLATE), str(files["v5"]), "--peak", "9kG:10%", "--channel",
                 "3"]) == 2
    assert ("--channel: found '3', expected one of the file's channels: accel, strain (or its "
            "number, 1 to 2)") in capsys.readouterr().err


def _mutations():
    from hypothesis import strategies as st

    return st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 255)), min_size=1,
                    max_size=12), st.integers(0, 10**6)


@pytest.mark.parametrize("kind", ["v5", "fs", "v73", "ascii", "binary", "mme", "ide"])
def test_any_damage_to_a_recording_is_a_trace_or_one_error(pulse, kind):
    """Bytes overwritten anywhere, and the file cut anywhere (hypothesis, derandomized): the
    reader gives a Trace or one AirgunXlError, never another exception or a warning."""
    import warnings

    from hypothesis import HealthCheck, given, settings

    from airgun_xl.readers.recording import read_trace

    folder, trace, files = pulse
    if kind not in files:
        pytest.skip("needs h5py, pyuff or idelib")
    good = files[kind].read_bytes()
    flips, cuts = _mutations()
    target = folder / f"damaged_{kind}{files[kind].suffix}"  # an MME channel file: .002

    @settings(max_examples=120, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(flips=flips, cut=cuts)
    def check(flips, cut):
        data = bytearray(good)
        for at, value in flips:
            data[at % len(data)] = value
        target.write_bytes(bytes(data[: max(1, len(data) - cut % len(data))]))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                read_trace(target)
            except airgun_xl.AirgunXlError as exc:
                assert "\n" not in str(exc)

    check()


@pytest.mark.parametrize("compressed", [True, False])
@pytest.mark.parametrize("oned_as", ["row", "column"])
def test_our_mat5_reader_reads_what_scipy_writes_as_scipy_reads_it(tmp_path, compressed,
                                                                  oned_as):
    """airgun_xl.readers.formats.mat5 (ours, bounded: scipy's reader crashes on damaged
    files) against scipy.io's whosmat and loadmat on a file savemat writes: every variable's
    shape and class, every numeric and text variable's values bit for bit; a cell and a
    structure listed and skipped."""
    from scipy.io import loadmat, whosmat

    from airgun_xl.readers.formats.mat5 import Mat5

    rng = np.random.default_rng(5)
    variables = {"f64": rng.normal(size=300), "f32": rng.normal(size=7).astype(np.float32),
                 "i16": rng.integers(-300, 300, 40).astype(np.int16),
                 "u8": rng.integers(0, 255, 9).astype(np.uint8),
                 "i64": rng.integers(-2**40, 2**40, 5), "z": rng.normal(size=6) + 1j,
                 "scalar": 51_200.0, "unit": "m/s²", "grid": rng.normal(size=(3, 4)),
                 "cell": np.array([1, "a"], dtype=object), "s": {"a": 1.0, "b": "x"}}
    path = tmp_path / "all.mat"
    savemat(path, variables, do_compression=compressed, oned_as=oned_as)
    data = path.read_bytes()
    ours = Mat5(data, 10**6)
    theirs = {name: (shape, kind) for name, shape, kind in whosmat(path)}
    # whosmat gives a text's shape as a string's, (1,); ours is as stored, 1 x 4 characters
    assert {n: (v.shape if v.kind != "char" else (1,), v.kind)
            for n, v in ours.variables.items()} == theirs
    assert ours.variables["unit"].shape == (1, 4)
    loaded = loadmat(path)
    for name in ("f64", "f32", "i16", "u8", "i64", "z", "scalar", "grid"):
        expected = loaded[name]
        got = ours.values(name)
        assert got.dtype == expected.dtype and np.array_equal(
            got, expected.ravel(order="F")), name
    assert str(ours.values("unit")) == "m/s²" == loaded["unit"][0]


def test_a_uffs_time_responses_are_listed_and_a_lying_point_count_is_one_line(pulse, tmp_path,
                                                                              capsys):
    """``recording`` lists a UFF file's time responses (name from ID line 1, unit from the
    ordinate's label, the rate of its stored increment); a header whose point count is not
    what the dataset holds, a file with no time response, and one cut short are one line."""
    folder, trace, files = pulse
    if "binary" not in files:
        pytest.skip("needs pyuff")
    for kind in ("ascii", "binary"):
        assert main(["recording", str(files[kind]), "--json"]) == 0
        listed = json.loads(capsys.readouterr().out)
        assert listed["format"] == "UFF dataset 58"
        assert [(c["name"], c["unit"]) for c in listed["channels"]] == [
            ("temperature", "C"), ("accel", "g")]
        step = float(f"{trace.time[1] - trace.time[0]:.5E}")
        assert listed["channels"][1]["rate_hz"] == pytest.approx(1 / step, rel=1e-12)
    text = files["ascii"].read_text()
    header = f"{4:10d}{len(trace.time):10d}{1:10d}"
    assert text.count(header) == 2
    lying = tmp_path / "lying.uff"
    lying.write_text(text.replace(header, f"{4:10d}{len(trace.time) + 7:10d}{1:10d}"))
    assert main(["accept", str(TEMPLATE), str(lying), "--peak", "9kG:10%", "--channel",
                 "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and (f"time response 'accel' declares {len(trace.time) + 7:,} "
                                     f"points and holds {len(trace.time):,}") in err, err
    none = tmp_path / "none.uff"
    none.write_text(text.replace(f"{1:5d}{0:10d}{0:5d}{0:10d}       BIRD",
                                 f"{2:5d}{0:10d}{0:5d}{0:10d}       BIRD"))
    assert main(["accept", str(TEMPLATE), str(none), "--peak", "9kG:10%"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "has no dataset 58 time response" in err, err
    # listed, one line too (it listed "0 channels" with exit 0: issue 62)
    assert main(["recording", str(none)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1, captured
    assert "holds no channel of a recording (a time response)" in captured.err
    data = files["binary"].read_bytes()
    for cut in range(1, 10):
        short = tmp_path / f"cut{cut}.uff"
        short.write_bytes(data[: len(data) * cut // 10])
        code = main(["accept", str(TEMPLATE), str(short), "--peak", "9kG:10%", "--channel",
                     "accel"])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1, (cut, err)


def test_a_unit_given_over_the_files_is_named_where_the_figures_go(pulse, tmp_path):
    """--accel-unit over a file that states another unit reads the values in the given unit
    and says so: the warning is in the verdict (and so on its pages and its record); the same
    unit spelled another way (m/s2 for m/s^2, µs for us) is no conflict."""
    folder, trace, files = pulse
    given = airgun_xl.accept(TEMPLATE, files["csv"], **SPEC, accel_unit="g")
    note = (f"{files['csv']}: --accel-unit g replaces the unit the file states (kG): its "
            "values are read as g")
    assert note in given.verdict.warnings
    assert given.verdict.word == "FAIL"  # a thousandth of the pulse: the peak far below
    same = airgun_xl.accept(TEMPLATE, files["csv"], **SPEC, accel_unit="kG")
    assert not [w for w in same.verdict.warnings if "replaces the unit" in w]
    spelled = tmp_path / "us.csv"  # the times in µs, so that the rate stays the recorder's
    spelled.write_text("time [µs],acceleration [m/s2]\n" + "".join(
        f"{t * 1e6!r},{a!r}\n" for t, a in zip(trace.time.tolist(), trace.accel_kg.tolist(),
                                              strict=True)))
    from airgun_xl.readers.recording import read_trace

    assert read_trace(spelled, time_unit="us", accel_unit="m/s^2").notes == []
    compared = airgun_xl.compare_measured(TEMPLATE, files["v5"], accel_unit="g")
    assert any("--accel-unit g replaces the unit the file states (kG)" in w
               for w in compared.warnings)


@pytest.mark.parametrize("unit, per_g", [("G", 1.0), ("g's", 1.0), ("m/s**2", G),
                                         ("mm/ms^2", G / 1000), ("mm/ms²", G / 1000),
                                         ("m/sec^2", G)])
def test_a_files_unit_in_a_recorders_spelling_is_read(tmp_path, unit, per_g):
    """The spellings recorders write (G, mm/ms^2, m/s**2) read as the unit they mean: the
    same pulse in each gives the same accelerations as in g, to a product's rounding."""
    from airgun_xl.readers.recording import read_trace

    t = np.arange(64) / 1e4
    g = 100 * np.sin(np.pi * t / t[-1])
    path = tmp_path / "r.mat"
    savemat(path, {"fs": 1e4, "accel": g * per_g, "accel_unit": unit})
    reference = tmp_path / "g.mat"
    savemat(reference, {"fs": 1e4, "accel": g, "accel_unit": "g"})
    assert read_trace(path).accel_kg == pytest.approx(read_trace(reference).accel_kg,
                                                      rel=1e-14)


def test_a_unit_a_case_away_is_still_refused_from_a_file(tmp_path, capsys):
    """KG is not kG (nor G): a file stating it is one line asking for the unit."""
    path = tmp_path / "r.mat"
    savemat(path, {"fs": 1e4, "accel": np.ones(64), "accel_unit": "KG"})
    assert main(["accept", str(TEMPLATE), str(path), "--peak", "9kG:10%"]) == 2
    assert "names 'KG', a case away from 'kG'" in capsys.readouterr().err


def test_an_mdf_files_channels_keep_their_own_rates_and_damage_is_one_line(pulse, tmp_path,
                                                                          capsys):
    """``recording`` lists each MDF channel on its own group's time base (1 kHz and 51.2
    kHz); a channel chosen by number; damaged copies (read in a child process: asammdf
    crashed the process on such files) give a verdict or one line, never a traceback or the
    library's own output."""
    folder, trace, files = pulse
    if "mdf" not in files:
        pytest.skip("needs asammdf")
    assert main(["recording", str(files["mdf"]), "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert listed["format"] == "ASAM MDF"
    assert [(c["name"], c["unit"], c["samples"]) for c in listed["channels"]] == [
        ("temperature", "degC", 50), ("accel", "g", len(trace.time))]
    assert listed["channels"][0]["rate_hz"] == pytest.approx(1000, rel=1e-12)
    assert listed["channels"][1]["rate_hz"] == pytest.approx(51_200, rel=1e-9)
    assert listed["channels"][1]["start_s"] == trace.time[0]
    by_number = airgun_xl.accept(TEMPLATE, files["mdf"], **SPEC, channel="2")
    assert by_number.verdict.word == "PASS"
    good = files["mdf"].read_bytes()
    rng = np.random.default_rng(1)
    for k in range(6):
        damaged = bytearray(good)
        for at in rng.integers(0, len(good), 12):
            damaged[at] = int(rng.integers(0, 256))
        path = tmp_path / f"damaged{k}.mf4"
        path.write_bytes(bytes(damaged[: len(good) - int(rng.integers(0, len(good) // 2))]))
        code = main(["accept", str(TEMPLATE), str(path), "--peak", "9kG:10%", "--channel",
                     "accel"])
        err = capsys.readouterr().err
        assert code in (0, 2, 3) and (code != 2 or err.count("\n") == 1), (k, err)
        assert "Traceback" not in err and "Exception ignored" not in err, (k, err)


@pytest.mark.skipif(os.name != "posix", reason="the stand-in interpreter is a shell script")
@pytest.mark.parametrize("script, message", [
    ("kill -SEGV $$", "the MDF reader (asammdf) stopped on this file (exit -11)"),
    ("exec sleep 30", "the MDF reader (asammdf) took over 1 s on this file"),
    ("echo 'not json'", "the MDF reader's reply is not readable"),
])
def test_the_mdf_childs_crash_hang_or_garbage_is_one_line(tmp_path, monkeypatch, script,
                                                          message):
    """The child process's end, whatever it is, is one WorkbookError line naming the file: a
    crash (a stand-in interpreter that kills itself with SIGSEGV), a hang past the timeout
    (killed), a reply that is not the protocol's."""
    import sys

    from airgun_xl.readers.formats import mdf

    stand_in = tmp_path / "python"
    stand_in.write_text(f"#!/bin/sh\ncat > /dev/null\n{script}\n")
    stand_in.chmod(0o755)
    monkeypatch.setattr(sys, "executable", str(stand_in))
    monkeypatch.setattr(mdf, "TIMEOUT", 1.0)
    path = tmp_path / "r.mf4"
    path.write_bytes(b"MDF     4.10    " + bytes(64))
    with pytest.raises(airgun_xl.WorkbookError) as caught:
        mdf.read(path, path.read_bytes(), None)
    assert str(caught.value).startswith(f"{path}: {message}"), str(caught.value)


def _write_mme(folder, t, g, encoding="utf-8-sig", explicit=False, unit="g", count=None):
    """An ISO 13499 MME test in the standard's layout: TEST.mme, Channel/TEST.chn and a
    channel file each (a temperature, then the pulse), header fields as ``Name :value``
    with NOVALUE where a field is not given, the samples one a line (the time implicit) or
    time and value a line (explicit)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "Channel").mkdir(exist_ok=True)
    (folder / "TEST.mme").write_bytes(
        "Data format edition number  :1.6\nLaboratory name             :Air gun lab\n"
        "Title                       :Bird shot 17 (°C, ±)\nNumber of channels          :2\n"
        .encode(encoding))
    (folder / "Channel" / "TEST.chn").write_bytes(
        "Instrumentation standard    :NOVALUE\nNumber of channels          :2\n"
        "Name of channel 001         :Temperature\nName of channel 002         :Bird X\n"
        .encode(encoding))

    def channel(name, code, values, unit):
        lines = ["Instrumentation standard    :NOVALUE",
                 f"Name of the channel         :{name}",
                 "Laboratory channel code     :NOVALUE",
                 f"Channel code                :{code}",
                 f"Unit                        :{unit}",
                 f"Time of first sample        :{'NOVALUE' if explicit else repr(float(t[0]))}",
                 f"Sampling interval           :"
                 f"{'NOVALUE' if explicit else repr(float(t[1] - t[0]))}",
                 f"Number of samples           :{len(values) if count is None else count}",
                 "Channel frequency class     :NOVALUE"]
        rows = ([f"{x!r} {y!r}" for x, y in zip(t.tolist(), values.tolist(), strict=True)]
                if explicit else [repr(y) for y in values.tolist()])
        return ("\n".join(lines + rows) + "\n").encode(encoding)

    (folder / "Channel" / "TEST.001").write_bytes(
        channel("Temperature °C", "00TEMP000000TE00", np.full(len(t), 21.0), "°C"))
    (folder / "Channel" / "TEST.002").write_bytes(
        channel("Bird X", "10BIRD0000XXACXP", g, unit))
    return folder / "TEST.mme"


@pytest.mark.parametrize("encoding", ["utf-8-sig", "cp1252", "latin-1"])
@pytest.mark.parametrize("explicit", [False, True])
def test_an_mme_test_gives_the_csvs_verdict(pulse, tmp_path, encoding, explicit):
    """The pulse as an MME test, in each encoding, its time implicit (the header's first
    sample and interval) or explicit: accept gives the CSV's verdict, every figure within a
    product's rounding (the time t0 + k dt, the g to kG); chosen by name, channel code or
    number alike."""
    folder, trace, files = pulse
    g = trace.accel_kg / KG_PER_G
    mme = _write_mme(tmp_path / "t", trace.time, g, encoding, explicit, unit="m/s²"
                     if encoding != "utf-8-sig" else "g")
    if encoding != "utf-8-sig":  # the same pulse in m/s² (the unit's ² in the encoding)
        mme = _write_mme(tmp_path / "t", trace.time, g * G, encoding, explicit, unit="m/s²")
    reference = airgun_xl.accept(TEMPLATE, files["csv"], **SPEC)
    verdicts = [airgun_xl.accept(TEMPLATE, mme, **SPEC, channel=c)
                for c in ("Bird X", "10BIRD0000XXACXP", "2")]
    for found in verdicts:
        assert found.verdict.word == reference.verdict.word == "PASS"
        for mine, theirs in zip(found.verdict.criteria, reference.verdict.criteria,
                                strict=True):
            assert mine.value == pytest.approx(theirs.value, rel=1e-12), mine.name
    listed = airgun_xl.recording(mme)
    assert listed.format == "ISO 13499 MME"
    assert [(c.name, c.unit) for c in listed.channels] == [
        ("Temperature °C", "°C"), ("Bird X", "m/s²" if encoding != "utf-8-sig" else "g")]
    # one channel file named alone is that channel
    alone = airgun_xl.accept(TEMPLATE, mme.parent / "Channel" / "TEST.002", **SPEC)
    assert [c.value for c in alone.verdict.criteria] == [
        c.value for c in verdicts[0].verdict.criteria]


def test_an_mme_export_in_nhtsas_layout_is_told_by_content_and_read(pulse, tmp_path):
    """The layout of NHTSA's MME exports (as pyisomme's test data holds them): the test file
    opens with ``Data format :ISO-MME``, the channel file with ``Channel code``, its header
    holds some 30 fields in the agency's order (a field name run into its colon,
    ``Transducer natural frequency:NOVALUE``, a tab before a colon in the test file), the
    test's name in lower case, the samples as E-format numbers. Told by its content under any
    name, it gives the verdict of a CSV of the same samples."""
    folder, trace, files = pulse
    g = np.array([float(f"{v:.6E}") for v in (trace.accel_kg / KG_PER_G).tolist()])
    test = tmp_path / "nhtsa"
    (test / "Channel").mkdir(parents=True)
    (test / "test.mme").write_text(
        "Data format                 :ISO-MME\nVersion                     :1.6\n"
        "Test number                 :test\nMovie reference\t\t:NOVALUE\n\n"
        "Comments                    :Time zero: first contact\n")
    (test / "Channel" / "test.chn").write_text(
        "Instrumentation standard    :SAEJ211, issued 1992\nNumber of channels          :1\n"
        "Name of channel 001         :10BIRD0000XXACXP / Bird X acceleration\n")
    dt = float(trace.time[1] - trace.time[0])
    fields = [("Channel code", "10BIRD0000XXACXP"), ("Laboratory channel code", "NOVALUE"),
              ("Reference channel", "implicit"), ("Reference channel name", "NOVALUE"),
              ("Data source", "transducer"), ("Test object number", "1"),
              ("Name of the channel", "Bird X acceleration"), ("Direction", "X"),
              ("Pre-filter type", "2000"), ("Channel frequency class", "NOVALUE"),
              ("Transducer natural frequency", "NOVALUE"), ("Channel amplitude class", "1000"),
              ("Sampling interval", repr(dt)), ("Unit", "g"),
              ("Time of first sample", repr(float(trace.time[0]))),
              ("Number of samples", str(len(g))), ("First global maximum value", "9.0E+2"),
              ("Dimension", "AC"), ("Bit resolution", "16"), ("Data status", "ok")]
    (test / "Channel" / "test.001").write_text("".join(
        f"{name:<28}:{value}\n" for name, value in fields) + "".join(f"{v:.6E}\n" for v in g))
    renamed = tmp_path / "shot17.txt"  # told by its content, not its name
    renamed.write_bytes((test / "Channel" / "test.001").read_bytes())
    ref = tmp_path / "ref.csv"
    ref.write_text("time [s],acceleration [g]\n" + "".join(
        f"{float(trace.time[0]) + k * dt!r},{v!r}\n" for k, v in enumerate(g.tolist())))
    reference = airgun_xl.accept(TEMPLATE, ref, **SPEC)
    for source in (test / "test.mme", test / "Channel" / "test.001", renamed):
        assert airgun_xl.recording(source).format == "ISO 13499 MME"
        found = airgun_xl.accept(TEMPLATE, source, **SPEC)
        assert found.verdict.word == reference.verdict.word == "PASS"
        for mine, theirs in zip(found.verdict.criteria, reference.verdict.criteria,
                                strict=True):
            assert mine.value == pytest.approx(theirs.value, rel=1e-12), mine.name


def test_an_mme_channels_explicit_time_is_its_reference_channel(pulse, tmp_path, capsys):
    """``Reference channel :explicit``: the time is the values of the channel that
    ``Reference channel name`` names (here by its code, a time channel in ms, as NHTSA's
    tests list a ``Time reference`` channel first). The verdict is the CSV's of those times
    and values, from the test and from the channel file named alone; a reference the test
    does not hold, or one of another length, is one line."""
    folder, trace, files = pulse
    g = trace.accel_kg / KG_PER_G
    ms = trace.time * 1e3
    test = tmp_path / "explicit"
    (test / "Channel").mkdir(parents=True)
    (test / "T1.mme").write_text("Data format                 :ISO-MME\n")

    def channel(code, name, unit, values, reference="NOVALUE"):
        fields = [("Channel code", code), ("Reference channel",
                                           "explicit" if reference != "NOVALUE" else "implicit"),
                  ("Reference channel name", reference), ("Name of the channel", name),
                  ("Sampling interval", "NOVALUE"), ("Unit", unit),
                  ("Time of first sample", "NOVALUE"), ("Number of samples", str(len(values)))]
        return "".join(f"{k:<28}:{v}\n" for k, v in fields) + "".join(
            f"{v!r}\n" for v in values.tolist())

    (test / "Channel" / "T1.001").write_text(channel("11TIRS000000TIRP", "Time reference",
                                                     "ms", ms))
    (test / "Channel" / "T1.002").write_text(channel("10BIRD0000XXACXP", "Bird X", "g", g,
                                                     "11TIRS000000TIRP"))
    ref = tmp_path / "ref.csv"
    ref.write_text("time [ms],acceleration [g]\n" + "".join(
        f"{x!r},{y!r}\n" for x, y in zip(ms.tolist(), g.tolist(), strict=True)))
    reference = airgun_xl.accept(TEMPLATE, ref, **SPEC)
    for source, channel_option in ((test / "T1.mme", "Bird X"),
                                   (test / "Channel" / "T1.002", None)):
        found = airgun_xl.accept(TEMPLATE, source, **SPEC, channel=channel_option)
        assert found.verdict.word == reference.verdict.word == "PASS"
        # the CSV's numbers are parsed by pandas, the MME's by Python: the same to the last
        # bit on the newest versions, an ulp apart on the lowest (numpy 1.26, pandas 2.1)
        for mine, theirs in zip(found.verdict.criteria, reference.verdict.criteria,
                                strict=True):
            assert mine.value == pytest.approx(theirs.value, rel=1e-12), mine.name
    (test / "Channel" / "T1.001").write_text(channel("11TIRS000000TIRP", "Time reference",
                                                     "ms", ms[:-1]))
    assert main(["accept", str(TEMPLATE), str(test / "T1.mme"), "--channel", "Bird X",
                 "--peak", "9kG:10%"]) == 2
    assert (f"holds {len(g):,} samples and its reference channel '11TIRS000000TIRP' "
            f"{len(g) - 1:,} times") in capsys.readouterr().err
    (test / "Channel" / "T1.001").unlink()
    (test / "Channel" / "T1.002").rename(test / "Channel" / "T1.001")
    assert main(["accept", str(TEMPLATE), str(test / "T1.mme"), "--peak", "9kG:10%"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "its time is explicit, in the reference channel '11TIRS000000TIRP', which the " \
        "test does not hold" in err


def test_an_mme_test_that_lies_or_links_out_is_one_line(pulse, tmp_path, capsys):
    """A sample count that is not the lines there are, a channel file that is a symlink (to
    a file outside the test) or a FIFO, and a Channel folder that is a symlink: one line
    each, exit 2, and nothing outside the test's folder read."""
    folder, trace, files = pulse
    g = trace.accel_kg / KG_PER_G

    def refused(mme, said):
        assert main(["accept", str(TEMPLATE), str(mme), "--peak", "9kG:10%", "--channel",
                     "Bird X"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err

    lying = _write_mme(tmp_path / "lying", trace.time, g, count=len(g) + 3)
    refused(lying, f"declares {len(g) + 3:,} samples and holds {len(g):,}")
    huge = _write_mme(tmp_path / "huge", trace.time, g, count=10**12)
    refused(huge, "channel 'Bird X' declares 1,000,000,000,000 samples, expected at most")
    linked = _write_mme(tmp_path / "linked", trace.time, g)
    outside = tmp_path / "outside.002"
    outside.write_bytes((linked.parent / "Channel" / "TEST.002").read_bytes())
    (linked.parent / "Channel" / "TEST.002").unlink()
    (linked.parent / "Channel" / "TEST.002").symlink_to(outside)
    refused(linked, "TEST.002: is not a regular file (a symlink or a device)")
    fifo = _write_mme(tmp_path / "fifo", trace.time, g)
    (fifo.parent / "Channel" / "TEST.002").unlink()
    os.mkfifo(fifo.parent / "Channel" / "TEST.002")
    refused(fifo, "TEST.002: is not a regular file (a symlink or a device)")
    moved = _write_mme(tmp_path / "moved", trace.time, g)
    (moved.parent / "Channel").rename(tmp_path / "elsewhere")
    (moved.parent / "Channel").symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    refused(moved, "its Channel folder is not a folder (a symlink or a file)")


@pytest.mark.skipif(not hasattr(os, "O_NOFOLLOW"), reason="the platform has no O_NOFOLLOW")
def test_a_channel_file_linked_after_the_check_is_refused_at_its_open(tmp_path):
    """An MME channel file is opened with O_NOFOLLOW: a symlink put there after the folder
    was listed (a check-then-open race) is refused by the open itself, in one line."""
    from airgun_xl.readers.guard import read_bytes

    target = tmp_path / "secret.txt"
    target.write_text("outside the test")
    link = tmp_path / "TEST.002"
    link.symlink_to(target)
    assert read_bytes(link, head=16) == b"outside the test"  # an input named by the user
    with pytest.raises(airgun_xl.WorkbookError, match=r"TEST\.002: cannot be read \("):
        read_bytes(link, head=16, follow=False)


def test_a_csv_in_a_recorders_time_unit_is_listed_with_its_rate(tmp_path):
    """The listing reads a CSV's units as the reader does (``sec`` is a file's spelling of
    s): its rate and start are known, not left blank."""
    path = tmp_path / "r.csv"
    path.write_text("time [sec],acceleration [G]\n" + "".join(
        f"{k / 1e4!r},{float(k % 7)!r}\n" for k in range(64)))
    (channel,) = airgun_xl.recording(path).channels
    assert (channel.unit, channel.samples, channel.start) == ("G", 64, 0.0)
    assert channel.rate == pytest.approx(1e4, rel=1e-12)


# -- a file far larger than the pulse ----------------------------------------------------------
def _long_recording(trace, before, after, seed=5):
    """The pulse of ``trace`` (kG) in g with ``before`` and ``after`` samples of rest noise
    around it on the same time base, as a recorder left running writes it (the noise white,
    1 % of the peak, as synthetic_measurement's)."""
    rng = np.random.default_rng(seed)
    g = trace.accel_kg / KG_PER_G
    dt = float(trace.time[1] - trace.time[0])
    rest = 0.01 * float(np.max(np.abs(g)))
    values = np.concatenate([rng.normal(0, rest, before), g, rng.normal(0, rest, after)])
    time = trace.time[0] + dt * (np.arange(len(values)) - before)
    return time, values


def _write_long(kind, path, time, g):
    """The recording in MDF (asammdf's writer) or TDMS (npTDMS's: a waveform from its
    first time at the median step)."""
    if kind == "mdf":
        return _write_mdf(path.with_suffix(".mf4"), time, g)
    import nptdms

    with nptdms.TdmsWriter(str(path.with_suffix(".tdms"))) as writer:
        writer.write_segment([nptdms.ChannelObject("Recorder", "accel", g, properties={
            "wf_increment": float(np.median(np.diff(time))), "wf_start_offset": float(time[0]),
            "unit_string": "g"})])
    return path.with_suffix(".tdms")


def _accel(kind):
    """The pulse's channel: the MDF file's second (a temperature first)."""
    return {"channel": "accel"} if kind == "mdf" else {}


WINDOWED = [pytest.param("mdf", marks=pytest.mark.skipif(_asammdf() is None,
                                                         reason="needs asammdf")), "tdms"]


@pytest.mark.parametrize("kind", WINDOWED)
def test_a_long_channel_is_read_around_its_pulse_and_said(pulse, tmp_path, monkeypatch, kind):
    """A channel longer than limits.MAX_SAMPLES (lowered here to 30,000; 2,000,000 as
    shipped, the rule the same) is scanned a chunk at a time and only the stretch around its
    largest excursion is read: half a second each side, at most the cap in all. The
    expected stretch is found here from the rule as docs/studies.md states it (the median of
    the first 10,000 samples as rest, the largest distance from it, (30,000 - 1) // 2 samples
    each side). accept gives, to the last bit, what it gives on a CSV of those samples, and
    the note that says what was read travels with the verdict."""
    from airgun_xl import limits
    from airgun_xl.readers.formats import channels

    folder, trace, files = pulse
    monkeypatch.setattr(limits, "MAX_SAMPLES", 30_000)
    monkeypatch.setattr(channels, "SCAN_CHUNK", 7_000)  # several chunks, the peak in one
    time, g = _long_recording(trace, 40_000, 25_000)
    path = _write_long(kind, tmp_path / "long", time, g)
    peak = int(np.argmax(np.abs(g - np.median(g[:10_000]))))
    half = (30_000 - 1) // 2
    window = slice(peak - half, peak + half + 1)
    ref = tmp_path / "window.csv"
    ref.write_text("time [s],acceleration [g]\n" + "".join(
        f"{x!r},{y!r}\n" for x, y in zip(time[window].tolist(), g[window].tolist(),
                                         strict=True)))
    reference = airgun_xl.accept(TEMPLATE, ref, **SPEC)
    found = airgun_xl.accept(TEMPLATE, path, **SPEC, **_accel(kind))
    assert found.verdict.word == reference.verdict.word == "PASS"
    for mine, theirs in zip(found.verdict.criteria, reference.verdict.criteria, strict=True):
        assert mine.value == pytest.approx(theirs.value, rel=1e-12), mine.name
    said = [w for w in found.warnings if "read the 29,999 samples around its largest" in w]
    assert said and f"{len(g):,} samples" in said[0]
    assert f"{peak - half + 1:,} to {peak + half + 1:,}" in said[0]
    # a NaN far from the pulse is found by the scan and named by its place in the channel
    g[3] = np.nan
    path.unlink()
    _write_long(kind, path, time, g)
    with pytest.raises(airgun_xl.WorkbookError, match=r"long\.(mf4|tdms): channel 'accel' "
                       r"sample 4 is not finite"):
        airgun_xl.accept(TEMPLATE, path, **SPEC, **_accel(kind))


def test_a_tdms_sample_that_is_not_finite_is_named_counting_from_one(tmp_path, capsys):
    """As every other reader names it (a MAT file's 51st sample is sample 51): the 51st
    sample of a TDMS waveform, NaN, is sample 51 in the one line; nothing is written."""
    g = np.r_[np.ones(50), np.nan, np.ones(49)]
    path = _write_long("tdms", tmp_path / "r", 1e-4 * np.arange(100), g)
    out = tmp_path / "c.xlsx"
    assert main(["compare-measured", str(TEMPLATE), str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "channel 'accel' sample 51 is nan, expected finite" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.tdms"]


@pytest.mark.parametrize("kind", WINDOWED)
def test_a_file_past_the_input_cap_is_opened_by_the_reader(pulse, tmp_path, monkeypatch,
                                                           capsys, kind):
    """A file past limits.MAX_INPUT_BYTES (lowered here to 100 kB, above the template's
    size, below the 0.65 MB file's) is not read whole by the caller: the child opens it
    itself and gives the same verdict, to the last bit, as the same file read whole. The file
    it opens must be the one vetted: another file moved to its name, or a symlink there, is
    one line; past limits.MAX_WINDOWED_BYTES it is refused before it is opened."""
    from airgun_xl import limits
    from airgun_xl.readers import guard

    folder, trace, files = pulse
    path = _write_long(kind, tmp_path / "big", *_long_recording(trace, 20_000, 20_000))
    reference = airgun_xl.accept(TEMPLATE, path, **SPEC, **_accel(kind))
    monkeypatch.setattr(limits, "MAX_INPUT_BYTES", 100_000)
    assert path.stat().st_size > limits.MAX_INPUT_BYTES
    with pytest.raises(airgun_xl.WorkbookError, match="expected a recording of at most 0.1 MB"):
        guard.read_bytes(path, "expected", "recording")  # as any other format would be
    found = airgun_xl.accept(TEMPLATE, path, **SPEC, **_accel(kind))
    assert found.verdict.word == reference.verdict.word == "PASS"
    for mine, theirs in zip(found.verdict.criteria, reference.verdict.criteria, strict=True):
        assert mine.value == theirs.value, mine.name
    assert main(["recording", str(path)]) == 0
    assert "accel" in capsys.readouterr().out
    vetted = guard.large_file(path, "expected", "recording", limits.MAX_WINDOWED_BYTES)
    assert vetted is not None and vetted.size == path.stat().st_size
    other = tmp_path / "other.bin"
    other.write_bytes(path.read_bytes())
    os.replace(other, path)  # the same bytes, another file
    with pytest.raises(airgun_xl.WorkbookError, match=r"big\.\w+: changed while it was read"):
        guard.open_large(vetted)
    if hasattr(os, "O_NOFOLLOW"):
        link = tmp_path / f"link{path.suffix}"
        link.symlink_to(path)
        with pytest.raises(airgun_xl.WorkbookError, match=r"link\.\w+: cannot be read \("):
            guard.large_file(link, "expected", "recording", limits.MAX_WINDOWED_BYTES)
    monkeypatch.setattr(limits, "MAX_WINDOWED_BYTES", 200_000)
    out = tmp_path / "a.xlsx"
    assert main(["accept", str(TEMPLATE), str(path), "--peak", "9kG:10%", "-o", str(out),
                 "--channel", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not out.exists()
    assert f"{path.name}: is 0.{path.stat().st_size // 100_000} MB, expected a recording of at " \
        "most 0.2 MB" in err


def test_an_ide_files_subchannels_are_listed_and_an_undescribed_file_refused(pulse, tmp_path,
                                                                             capsys):
    """``recording`` lists each IDE subchannel as CHANNEL/SUBCHANNEL with the unit the file
    states and its rate measured from its time codes; the values read are the calibrated
    ones (the counts through the polynomial, not the counts). A file without recording
    properties is refused in one line, not read with idelib's guess of an old recorder's
    channels; so is one whose properties nest 20,000 deep."""
    folder, trace, files = pulse
    if "ide" not in files:
        pytest.skip("needs idelib")
    assert main(["recording", str(files["ide"]), "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert listed["format"] == "enDAQ IDE"
    assert [(c["name"], c["unit"], c["samples"]) for c in listed["channels"]] == [
        ("Temperature/T", "degC", 10), ("Acceleration/X", "g", len(trace.time))]
    assert listed["channels"][1]["rate_hz"] == pytest.approx(51_200, rel=1e-12)
    from airgun_xl.readers.recording import read_trace

    read = read_trace(files["ide"], channel="2")
    expected = np.loadtxt(files["ide_csv"], delimiter=",", skiprows=1)
    assert np.array_equal(read.accel_kg, expected[:, 1] * KG_PER_G)
    bare, _ = _write_ide(tmp_path / "bare.ide", tmp_path / "bare.csv",
                         trace.accel_kg / KG_PER_G, properties=False)
    out = tmp_path / "a.xlsx"
    assert main(["accept", str(TEMPLATE), str(bare), "--peak", "9kG:10%", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not out.exists()
    assert "bare.ide: has no recording properties (no channel described" in err
    # 20,000 recording properties, each inside the last (EBML nests): one line as well
    from ebmlite import loadSchema

    nested = b""
    for _ in range(20_000):  # the element's ID, an 8-byte size, its payload
        nested = bytes.fromhex("18526570") + b"\x01" + len(nested).to_bytes(7, "big") + nested
    deep = tmp_path / "deep.ide"
    deep.write_bytes(loadSchema("mide_ide.xml").encodes([], headers=True) + nested)
    assert main(["recording", str(deep)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "deep.ide: has no recording properties" in err


def test_every_format_joins_one_registry_behind_one_interface(pulse, tmp_path):
    """Issue 61: the binary formats, CSV and a workbook's column range offer the same
    interface (:class:`RecordingFormat`'s members, checked on each module), and ``detect``
    chooses each from the one registry: a range by its text (no file opened), a file by its
    content, else by its name, else CSV; the reference CSV and its range in a workbook list
    the same one channel."""
    import inspect

    import openpyxl

    from airgun_xl.readers import formats
    from airgun_xl.readers.formats import delimited, mme, workbook_range
    from airgun_xl.readers.recording import list_channels

    members = {"NAME", "SUFFIXES", "EXPECTED", "SEVERAL", "sniff", "named", "channels", "read"}
    assert members <= {n for n, _ in inspect.getmembers(formats.RecordingFormat)}
    for fmt in (*formats.FORMATS, formats.FALLBACK, workbook_range):
        assert all(hasattr(fmt, m) for m in members), fmt.NAME
        assert fmt.SEVERAL == (fmt in formats.FORMATS), fmt.NAME
    _folder, _trace, files = pulse
    assert formats.detect(files["csv"]) is delimited
    assert formats.detect("trace.xlsx:Sheet1!A:B") is workbook_range  # no such file: text
    named = tmp_path / "TEST.001"  # an MME channel file told by its name, not content
    named.write_bytes(b"\0" * 64)
    assert formats.detect(named) is mme
    book = openpyxl.Workbook()
    rows = np.loadtxt(files["csv"], delimiter=",", skiprows=1)
    header = files["csv"].read_text().splitlines()[0].split(",")
    book.active.append(header)
    for t, a in rows:
        book.active.append([float(t), float(a)])
    book.save(tmp_path / "r.xlsx")
    (one,) = list_channels(f"{tmp_path / 'r.xlsx'}:Sheet!A:B")
    csv = list_channels(files["csv"])[0]
    assert (one.name, one.unit, one.samples, one.start) == \
        (csv.name, csv.unit, csv.samples, csv.start)
    # the rate (n - 1) / (t_end - t_0): a workbook's writer may round the last time's last
    # digit (openpyxl's oldest supported version writes 15 significant digits), which the
    # quotient carries (8.5e-16 relative was seen); 1e-12 is far inside any rate's meaning
    assert one.rate == pytest.approx(csv.rate, rel=1e-12)
