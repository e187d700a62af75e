"""Issue 62 (a first part): the channel a lab means, and what the messages say of it. With no
--channel, a file of several channels judges the first whose unit is an acceleration (said);
a file none of whose channels is one is refused naming each with its unit and --channel; a
binary file's unit is its channel's, never a "header"; the listing keeps its columns; a file
of no channel is refused; accept --srs names --srs; the SRS refusal's two figures differ as
their digits say; the TDMS record names its channel."""
import numpy as np
import pytest
from conftest import TEMPLATE
from scipy.io import savemat

from airgun_xl.cli import main
from airgun_xl.readers.recording import read_trace

RATE = 50_000.0


def refused(capsys, argv, folder, naming=()):
    """``main(argv)`` refuses in one line (exit 2, no traceback) naming each of ``naming``,
    and writes nothing under ``folder``."""
    before = sorted(p.name for p in folder.rglob("*"))
    capsys.readouterr()
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    for word in naming:
        assert word in lines[0], (word, lines[0])
    assert sorted(p.name for p in folder.rglob("*")) == before
    return lines[0]


def _pulse_g(n=2000):
    g = np.zeros(n)
    g[n // 4: n // 2] = 1000.0 * np.sin(np.linspace(0.0, np.pi, n // 4))
    return g


def _mat(path, **channels):
    """A .mat recording at RATE of ``channels`` ({name: (values, unit)}), in that order."""
    variables = {"fs": RATE}
    for name, (values, unit) in channels.items():
        variables[name] = values
        variables[f"{name}_unit"] = unit
    savemat(path, variables)
    return path


def test_a_file_whose_first_channel_is_a_strain_gauge_judges_its_acceleration(tmp_path):
    path = _mat(tmp_path / "r.mat", strain=(np.linspace(0, 1, 2000), "-"),
                accel=(_pulse_g(), "g"))
    trace = read_trace(path)
    assert trace.name.endswith("(accel)")
    assert np.array_equal(trace.accel_kg, read_trace(path, channel="accel").accel_kg)
    assert any("channel 'accel' is judged, the first of its 2 channels whose unit is an "
               "acceleration (g); --channel names another" in n for n in trace.notes)
    # where the first is one, it is judged as always, and nothing is said
    first = _mat(tmp_path / "f.mat", accel=(_pulse_g(), "g"), strain=(np.ones(2000), "-"))
    assert read_trace(first).notes == []


def test_a_file_of_no_acceleration_channel_lists_them_and_names_channel(tmp_path, capsys):
    path = _mat(tmp_path / "r.mat", strain=(np.linspace(0, 1, 2000), "-"),
                temp=(_pulse_g(), "C"))
    refused(capsys, ["accept", TEMPLATE, path, "--peak", "1000g:10%", "-o",
                     tmp_path / "v.xlsx"], tmp_path,
            naming=("--channel: ", "holds 2 channels and none states an acceleration unit "
                    "(1. 'strain' [-]; 2. 'temp' [C])", "expected --channel"))


def test_a_binary_channels_unit_is_its_own_never_a_header(tmp_path, capsys):
    path = _mat(tmp_path / "r.mat", strain=(_pulse_g(), "-"))
    said = refused(capsys, ["accept", TEMPLATE, path, "--peak", "1000g:10%", "-o",
                            tmp_path / "v.xlsx"], tmp_path,
                   naming=("--accel-unit: channel 'strain' of", "states the unit '-'",
                           "--channel"))
    assert "header" not in said


def test_the_listing_keeps_its_columns_whatever_the_names_length(tmp_path, capsys):
    """A 32-character name ran into the unit column (24 wide): the columns widen to it."""
    name = "accel_long_name_of_the_channel_x"
    path = _mat(tmp_path / "r.mat", **{name: (_pulse_g(), "g")})
    capsys.readouterr()
    assert main(["recording", str(path)]) == 0
    header, row = capsys.readouterr().out.splitlines()[1:3]
    assert row.split()[1:3] == [name, "g"]
    assert row.index(" g ") + 1 == header.index("unit")


def test_a_uff_of_no_time_response_is_refused(tmp_path, capsys):
    pyuff = pytest.importorskip("pyuff")
    path = tmp_path / "r.uff"
    uff = pyuff.UFF(str(path))
    uff.write_sets({"type": 15, "node_nums": [1], "def_cs": [0], "disp_cs": [0],
                    "color": [1], "x": [0.0], "y": [0.0], "z": [0.0]}, mode="overwrite")
    said = refused(capsys, ["recording", path], tmp_path)
    assert said.endswith("r.uff: holds no channel of a recording (a time response), expected "
                         "a UFF dataset 58 file of at least one")


def test_accept_srs_names_its_own_option(tmp_path, capsys):
    t = np.arange(0, 15e-3, 1e-5)
    rec = tmp_path / "r.csv"
    rec.write_text("time [s],acceleration [g]\n" + "".join(
        f"{float(a)!r},{float(b)!r}\n" for a, b in zip(t, _pulse_g(len(t)), strict=True)))
    req = tmp_path / "req.csv"
    req.write_text("frequency [rpm],srs [g]\n100,10\n1000,2000\n")
    said = refused(capsys, ["accept", TEMPLATE, rec, "--srs", req, "-o",
                            tmp_path / "v.xlsx"], tmp_path, naming=("--srs",))
    assert "--target-srs" not in said


def test_the_srs_refusal_never_contradicts_itself(tmp_path, capsys):
    """9.97 ms resolves 100.3 Hz: a row at 100 Hz was refused as "below the 100 Hz"."""
    t = np.arange(0, 9.98e-3, 1e-5)
    g = np.zeros(len(t))
    g[100:400] = 1000.0 * np.sin(np.linspace(0, np.pi, 300))
    rec = tmp_path / "r.csv"
    rec.write_text("time [s],acceleration [g]\n" + "".join(
        f"{float(a)!r},{float(b)!r}\n" for a, b in zip(t, g, strict=True)))
    req = tmp_path / "req.csv"
    req.write_text("frequency [Hz],srs [g]\n100,10\n1000,2000\n")
    said = refused(capsys, ["accept", TEMPLATE, rec, "--srs", req, "-o",
                            tmp_path / "v.xlsx"], tmp_path, naming=("--srs: found a row at",))
    assert "found a row at 100 Hz, below the 100.3 Hz the record's 9.97 ms" in said, said


def test_a_tdms_record_names_its_channel(tmp_path):
    nptdms = pytest.importorskip("nptdms")
    path = tmp_path / "r.tdms"
    with nptdms.TdmsWriter(str(path)) as writer:
        writer.write_segment([nptdms.ChannelObject(
            "Bird", "X", _pulse_g(), properties={"wf_increment": 1 / RATE,
                                                 "unit_string": "g"})])
    assert read_trace(path).name.endswith("r.tdms (Bird/X)")
