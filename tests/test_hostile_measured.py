"""Issue 23 (second hostile pass), the findings on measured recordings fixed in this pass: each
test is named after its finding."""
import numpy as np
import pytest
from conftest import TEMPLATE

from airgun_xl.cli import main

nptdms = pytest.importorskip("nptdms")


def _tdms(path, data, **properties):
    props = {"wf_increment": 1e-5, "wf_start_offset": 0.0, "unit_string": "g"}
    props.update(properties)
    with nptdms.TdmsWriter(str(path)) as writer:
        writer.write_segment([nptdms.ChannelObject("Recorder", "accel", data,
                                                   properties=props)])
    return path


def _pulse(n=600):
    t = np.arange(n) * 1e-5
    return np.where((t > 1e-3) & (t < 5e-3), 10000 * np.sin(np.pi * (t - 1e-3) / 4e-3), 0.0)


@pytest.mark.parametrize("properties", [{"wf_increment": "ten microseconds"},
                                        {"wf_start_offset": "yesterday"}])
def test_23_9_tdms_properties_of_the_wrong_type_are_one_line(tmp_path, capsys, properties):
    path = _tdms(tmp_path / "bad.tdms", _pulse(), **properties)
    out = tmp_path / "c.xlsx"
    assert main(["compare-measured", str(TEMPLATE), str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is not a waveform of numbers" in err
    assert "Traceback" not in err and not out.exists()


def test_23_9_a_string_channel_is_one_line(tmp_path, capsys):
    path = _tdms(tmp_path / "text.tdms", np.array(["a", "b"] * 300))
    assert main(["compare-measured", str(TEMPLATE), str(path), "-o",
                 str(tmp_path / "c.xlsx")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is not a waveform of numbers" in err


@pytest.mark.parametrize("name", ["accel (z)", "accel [z]"])
def test_23_18_a_channel_name_with_brackets_keeps_its_unit(tmp_path, capsys, name):
    """The channel's unit_string (g) is the unit, whatever brackets its name holds."""
    with nptdms.TdmsWriter(str(tmp_path / "n.tdms")) as writer:
        writer.write_segment([nptdms.ChannelObject("Recorder", name, _pulse(), properties={
            "wf_increment": 1e-5, "wf_start_offset": 0.0, "unit_string": "g"})])
    from airgun_xl.workbook.trace import read_trace

    trace = read_trace(tmp_path / "n.tdms")
    assert trace.units == ("s", "g")


@pytest.mark.parametrize("header, message", [
    ("time [ms],acceleration [Kg]", "names 'Kg', a case away from 'kG'"),
    ("time [MS],acceleration [g]", "names 'MS', a case away from 'ms'"),
])
def test_23_27_units_are_case_sensitive(tmp_path, capsys, header, message):
    """[Kg] is kilograms and [MS] is not milliseconds: refused, naming the near unit."""
    t = np.arange(400) * 0.01
    body = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(t, _pulse(400), strict=True))
    path = tmp_path / "m.csv"
    path.write_text(header + "\n" + body)
    assert main(["compare-measured", str(TEMPLATE), str(path), "-o",
                 str(tmp_path / "c.xlsx")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err
