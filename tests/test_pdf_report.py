"""Issue 46: the client's test report as a PDF (accept --pdf), read back with a PDF text
extractor (poppler's pdftotext) and rendered (pdftoppm): the verdict, every criterion with
its value, limits and margin, the warnings, the specification's sources, the charts drawn,
and the same bytes twice with --reproducible."""
import math
import re
import shutil
import subprocess

import numpy as np
import pytest
from conftest import TEMPLATE, write_trace_csv

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.crush_law import LEGACY_LAW
from airgun_xl.studies.calibrate import synthetic_measurement

pytest.importorskip("matplotlib")
needs_poppler = pytest.mark.skipif(not (shutil.which("pdftotext") and shutil.which("pdftoppm")),
                                   reason="needs poppler-utils (pdftotext, pdftoppm)")

#: Shot A fired on a lot 10 % stronger, recorded at 51.2 kHz with 1 % noise: judged on the
#: default record, 9.3337 kG and 4.7385 ms (tests/test_closed_loop.py's first shot).
PASSING = {"peak": "9.3kG:5%", "duration": "4.74ms:15%"}
FAILING = {"peak": "8.5kG:5%", "duration": "4.5ms:15%", "velocity-change": "8m/s:50%"}


@pytest.fixture(scope="module")
def fired(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pdf")
    shot = folder / "shot1.xlsx"
    shot.write_bytes(TEMPLATE.read_bytes())
    p = airgun_xl.load(shot).params.replace(crush_law=LEGACY_LAW.scaled(1.10))
    write_trace_csv(folder / "rec$x^2$.csv", synthetic_measurement(p, dt=1 / 51_200, seed=3))
    return folder, shot, folder / "rec$x^2$.csv"


def _accept(fired, spec, name, *extra):
    folder, shot, rec = fired
    pdf = folder / f"{name}.pdf"
    argv = ["accept", str(shot), str(rec), "-o", str(folder / f"{name}.xlsx"), "--pdf",
            str(pdf), "--force", "--quiet", *extra]
    for key, value in spec.items():
        argv += [f"--{key}", value]
    code = main(argv)
    return code, pdf


def _text(pdf):
    return subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True,
                          text=True, check=True).stdout


def _pages(pdf):
    return int(re.search(r"Pages:\s+(\d+)", subprocess.run(
        ["pdfinfo", str(pdf)], capture_output=True, text=True).stdout).group(1))


def _rows_of_colour(pdf, folder, rgb, tolerance):
    """The rows (a fraction of the page's height, from the top) of the last page, rendered
    by pdftoppm at 60 dpi, that hold a pixel of colour ``rgb`` (each channel within
    ``tolerance``: anti-aliased thin lines are lighter)."""
    from PIL import Image

    last = str(_pages(pdf))
    subprocess.run(["pdftoppm", "-r", "60", "-png", "-singlefile", "-f", last, "-l", last,
                    str(pdf), str(folder / "p")], check=True)
    pixels = np.asarray(Image.open(folder / "p.png").convert("RGB")).astype(int)
    found = np.all(np.abs(pixels - list(rgb)) < tolerance, axis=2)
    return np.flatnonzero(found.any(axis=1)) / len(pixels)


@needs_poppler
@pytest.mark.parametrize("case", ["PASS", "FAIL"])
def test_the_pdf_reads_back_the_verdict_criteria_warnings_and_sources(fired, case, capsys):
    code, pdf = _accept(fired, PASSING if case == "PASS" else FAILING, case.lower(),
                        "--reproducible")
    assert code == (0 if case == "PASS" else 3)
    folder, shot, rec = fired
    outcome = airgun_xl.accept(shot, rec, **{k.replace("-", "_"): v for k, v in (
        PASSING if case == "PASS" else FAILING).items()})
    text = _text(pdf)
    flat = " ".join(text.split())
    assert f"Verdict: {case}" in flat
    for c in outcome.criteria:  # the value, limits, margin and result as the terminal's
        row = re.search(rf"^{re.escape(c.name)}\s+(\S+(?: ± \S+)?)\s+{re.escape(c.unit)}\s+"
                        rf"(.+?)\s{{2,}}"
                        rf"(\S+ \S+)\s+(PASS|FAIL)$", text, re.M)
        assert row is not None, (c.name, text)
        # the value and its expanded uncertainty U (k = 2), as the terminal shows them
        assert row.group(1) == f"{c.value:.5g}" + (
            f" ± {c.expanded:.2g}" if math.isfinite(c.expanded) else "")
        assert row.group(2) == airgun_xl.studies.acceptance.limits_text(c)
        assert row.group(3) == f"{c.margin:+.2f} {c.margin_unit}"
        assert row.group(4) == ("PASS" if c.passed else "FAIL")
    for warning in outcome.warnings:
        assert " ".join(warning.split()) in flat, warning
    for source in outcome.verdict.sources():
        assert " ".join(source.split()) in flat, source
    pages = _pages(pdf)
    assert f"page 1 of {pages}" in flat and f"page {pages} of {pages}" in flat
    # a file's name is text: "$x^2$" is not typeset as mathematics
    assert "Recording: rec$x^2$.csv" in flat  # the header names the file
    assert "Name:" in flat and "Signature:" in flat and "Date:" in flat


@needs_poppler
def test_the_charts_page_renders_with_its_curves(fired, tmp_path):
    """The last page (pdftoppm at 60 dpi): the record's colour (#1f4e79) drawn in each of
    its three charts' bands of the page, not a blank page."""
    code, pdf = _accept(fired, FAILING, "charts", "--reproducible")
    assert code == 3
    rows = _rows_of_colour(pdf, tmp_path, (31, 78, 121), 40)
    # the pulse (top), the SRS and the pseudo-velocity (below): curve pixels in each third
    for lo, hi in ((0.05, 0.4), (0.4, 0.68), (0.68, 0.95)):
        assert np.any((rows > lo) & (rows < hi)), (lo, hi)


def test_the_same_run_twice_with_reproducible_gives_the_same_bytes(fired):
    first = _accept(fired, PASSING, "one", "--reproducible")[1].read_bytes()
    second = _accept(fired, PASSING, "two", "--reproducible")[1].read_bytes()
    assert first == second and first.startswith(b"%PDF")
    dated = _accept(fired, PASSING, "dated")[1].read_bytes()
    assert dated != first and b"/CreationDate" in dated and b"/CreationDate" not in first


@pytest.mark.parametrize("given", ["report.xlsx", "."])
def test_a_pdf_path_refused_is_one_line_and_nothing_written(fired, given, capsys, tmp_path):
    folder, shot, rec = fired
    out = tmp_path / "v.xlsx"
    target = str(tmp_path / given) if given != "." else str(tmp_path)
    code = main(["accept", str(shot), str(rec), "-o", str(out), "--pdf", target,
                 "--peak", "9.3kG:5%"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("airgun-xl: error: "), err
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@needs_poppler
def test_a_corridor_and_an_srs_requirement_are_on_the_pdf(tmp_path):
    """The README's recording of shot A judged against MIL-STD-810H's half-sine corridor and
    an SRS requirement with its dB tolerance: the corridor and SRS criteria read back, and
    the charts page draws the corridor's limits and the requirement's lines (in the
    failure colour, #9C0006) beside the record."""

    requirement = tmp_path / "req.csv"
    requirement.write_text("frequency [Hz],srs [g]\n200,150\n1000,1500\n4000,6000\n")
    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(TEMPLATE.read_bytes())
    pdf = tmp_path / "corridor.pdf"
    code = main(["accept", str(shot), str(TEMPLATE.parent / "shot_a_recording.csv"), "--sign",
                 "-1", "--cfc", "1000", "--profile", "mil-std-810h-half-sine", "--peak",
                 "9.5kG", "--duration", "5ms", "--srs", str(requirement), "--srs-tol",
                 "-40dB,+40dB", "--pdf", str(pdf), "--reproducible", "--quiet"])
    assert code in (0, 3)
    flat = " ".join(_text(pdf).split())
    assert re.search(r"corridor \S+(?: ± \S+)? % the record inside the band", flat), flat
    assert re.search(r"\bSRS \S+ dB -40 to 40 dB ", flat), flat
    # each criterion's detail under the table, as the terminal and the workbook say it
    # (issue 63: an SRS failure located by its frequencies, not its worst figure alone)
    outcome = airgun_xl.accept(shot, TEMPLATE.parent / "shot_a_recording.csv", sign=-1,
                               cfc=1000, profile="mil-std-810h-half-sine", peak="9.5kG",
                               duration="5ms", srs=str(requirement), srs_tol="-40dB,+40dB")
    for c in outcome.criteria:
        if c.detail:
            assert f"- {c.name}: " + " ".join(c.detail.split()) in flat, (c.name, c.detail)
    rows = _rows_of_colour(pdf, tmp_path, (156, 0, 6), 50)
    assert np.any(rows < 0.4) and np.any((rows > 0.4) & (rows < 0.68))  # corridor, SRS


@needs_poppler
@pytest.mark.parametrize("peak,unit", [("9300g:10%", "g"), ("9.5kG:10%", "kG"),
                                       (None, "g")])
def test_the_charts_are_in_the_clients_unit(peak, unit, tmp_path):
    """Issue 63: the pulse and the SRS are drawn in the unit the specification's peak was
    given in (a client who writes g reads g); with an SRS requirement and no peak, in g, as
    the workbook's SRS chart; the pseudo-velocity in m/s."""
    from airgun_xl.reports.pdf_report import chart_unit
    from airgun_xl.specification import Specification
    from airgun_xl.units import G_PER_KG

    requirement = tmp_path / "req.csv"
    requirement.write_text("frequency [Hz],srs [g]\n200,150\n1000,1500\n4000,6000\n")
    pdf = tmp_path / "unit.pdf"
    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(TEMPLATE.read_bytes())
    given = ["--peak", peak] if peak else []
    code = main(["accept", str(shot), str(TEMPLATE.parent / "shot_a_recording.csv"),
                 "--sign", "-1", "--cfc", "1000", *given, "--srs", str(requirement),
                 "--srs-tol", "-40dB,+40dB", "--pdf", str(pdf), "--reproducible", "--quiet"])
    assert code in (0, 3) and pdf.is_file()
    flat = " ".join(_text(pdf).split())
    assert flat.count(f"Acceleration ({unit})") == 2, flat  # the pulse's axis and the SRS's
    other = {"g", "kG"} - {unit}
    assert not any(f"Acceleration ({o})" in flat for o in other)
    assert "Velocity (m/s)" in flat
    # each source line once: "How it was judged" repeated the sources' lines
    outcome = airgun_xl.accept(shot, TEMPLATE.parent / "shot_a_recording.csv", sign=-1,
                               cfc=1000, srs=str(requirement), srs_tol="-40dB,+40dB",
                               **({"peak": peak} if peak else {}))
    for line in outcome.verdict.sources():
        assert flat.count(" ".join(line.split())) == 1, line
    assert chart_unit(Specification()) == ("kG", 1.0)
    assert chart_unit(Specification(units=(("peak", "g"),))) == ("g", pytest.approx(G_PER_KG))


@needs_poppler
def test_a_fills_pdf_holds_the_summarys_figures_the_verdict_and_the_charts(tmp_path):
    """fill --pdf: the Summary's figures as the sheet shows them (its number format: 11.994
    kG, 0.2885 ms...), the predicted verdict's criteria, the warnings (none here), and a
    charts page whose six charts are drawn; the same bytes twice with --reproducible."""

    from airgun_xl.reports.pdf_report import excel_number

    outs = []
    for k in range(2):
        out, pdf = tmp_path / f"f{k}.xlsx", tmp_path / f"f{k}.pdf"
        assert main(["fill", str(TEMPLATE), "-o", str(out), "--pdf", str(pdf), "--quiet",
                     "--reproducible", "--peak", "8.5kG:10%", "--duration", "5ms:10%"]) == 0
        outs.append(pdf.read_bytes())
    assert outs[0] == outs[1]
    flat = " ".join(_text(tmp_path / "f0.pdf").split())
    assert "Predicted verdict: PASS" in flat and "Warnings: none" in flat
    sheet = openpyxl_summary(tmp_path / "f0.xlsx")
    for label in ("Peak acceleration (raw)", "Time of peak", "Pulse duration",
                  "Maximum crush", "Final M1", "Dominant frequency 1", "Time step"):
        value, fmt, unit = sheet[label]
        assert f"{label} {excel_number(value, fmt)} {unit}" in flat, (label, value, fmt)
    # the record judged (the default low-pass at 6/D) peaks at 8.4573 kG; the raw 11.994 kG
    # is on the Summary as the model's
    assert re.search(r"peak 8\.4573 kG 7\.65 to 9\.35 kG \+9\.50 % PASS", flat), flat
    # the shot's inputs, every cell the run read (issue 63: a client reads the velocity, the
    # masses and the mitigator beside the figures), each as the Parameters sheet holds it
    params = airgun_xl.load(TEMPLATE).params
    from airgun_xl.xlsx.sheets import parameter_rows

    for cell, label, value, unit, _meaning in parameter_rows(params):
        shown = "blank" if value is None else f"{value:.7g}"
        assert f"{cell} {' '.join(label.split())} {shown} {unit}" in flat, (cell, label)
    assert "A28 " in flat and f"{params.v31:.7g} m/s" in flat
    rows = _rows_of_colour(tmp_path / "f0.pdf", tmp_path, (31, 78, 121), 40)
    for lo, hi in ((0.1, 0.35), (0.38, 0.62), (0.66, 0.92)):  # the three rows of charts
        assert np.any((rows > lo) & (rows < hi)), (lo, hi)


def openpyxl_summary(path):
    """{quantity: (value, number format, unit)} of a filled workbook's Summary sheet."""
    import openpyxl

    ws = openpyxl.load_workbook(path)["Summary"]
    return {r[0].value: (r[1].value, r[1].number_format, r[2].value or "")
            for r in ws.iter_rows(min_row=2) if isinstance(r[1].value, (int, float))}


def test_fill_pdf_is_refused_for_a_campaign_and_a_wrong_name(tmp_path, capsys):
    day = tmp_path / "day"
    day.mkdir()
    for name in ("a", "b"):
        (day / f"{name}.xlsx").write_bytes(TEMPLATE.read_bytes())
    assert main(["fill", str(day), "--pdf", str(tmp_path / "r.pdf"), "--jobs", "1"]) == 2
    assert "--pdf: found with 2 shots, expected one shot's workbook" in capsys.readouterr().err
    assert main(["fill", str(day / "a.xlsx"), "--pdf", str(tmp_path / "r.txt")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "r.txt: has the extension .txt, expected .pdf" in err[0]
    assert sorted(p.name for p in day.iterdir()) == ["a.xlsx", "b.xlsx"]
    assert not (tmp_path / "r.pdf").exists()


@needs_poppler
def test_design_and_next_put_their_study_on_the_pdf(fired, tmp_path):
    """design --confidence --pdf: the P(PASS) found and the setting, on the PDF as on the
    Summary; next --pdf: the proposal with its P(PASS), where the law and the gun's scatter
    came from; both files listed with the workbook."""
    folder, shot, rec = fired
    found = airgun_xl.design(TEMPLATE, peak="12kG:10%", duration="5ms:10%", confidence=0.5,
                             sd="A28=1.5%", shots=200, output=tmp_path / "d.xlsx",
                             pdf=tmp_path / "d.pdf")
    assert found.files == (tmp_path / "d.xlsx", tmp_path / "d.pdf")
    flat = " ".join(_text(tmp_path / "d.pdf").split())
    assert "The study behind this shot" in flat
    assert re.search(r"design --confidence 0\.5: P\(PASS\) = \d\.\d{4} \(95 % interval", flat)
    proposal = airgun_xl.next_shot(shot, rec, archive=tmp_path / "arch", lot="LOT-P",
                                   new_lot=True, sd="A28=1.5%", shots=100,
                                   output=tmp_path / "n.xlsx", pdf=tmp_path / "n.pdf",
                                   peak="8.5kG:5%", duration="4.5ms:15%")
    assert proposal.files == (tmp_path / "n.xlsx", tmp_path / "n.pdf")
    flat = " ".join(_text(tmp_path / "n.pdf").split())
    assert f"next shot of lot LOT-P: A28 = {proposal.setting:.6g} m/s" in flat
    assert " ".join(proposal.gun.split()) in flat
    # what the proposal expects there, and the lot's law against the report's (issue 60)
    assert "expected there (median, 90 % of the draws): peak " in flat
    assert re.search(r"the lot's law is x\d\.\d{4}( to x\d\.\d{4})? the report's", flat)


def test_design_pdf_without_a_workbook_is_refused_before_the_study(tmp_path):
    with pytest.raises(airgun_xl.OptionError, match="--pdf: found without a workbook"):
        airgun_xl.design(TEMPLATE, target_peak="12kG", pdf=tmp_path / "d.pdf")
    assert list(tmp_path.iterdir()) == []


@needs_poppler
def test_a_name_the_font_cannot_draw_is_written_by_code_point_without_a_library_warning(
        fired, tmp_path, capsys):
    """A recording named in CJK: DejaVu Sans has no glyph for it, so matplotlib would draw
    empty boxes and warn on the user's terminal; the PDF writes each such character as its
    code point instead (exact, readable), and stderr holds no library warning."""
    folder, shot, rec = fired
    named = tmp_path / "测试.csv"
    named.write_bytes(rec.read_bytes())
    code = main(["accept", str(shot), str(named), "--pdf", str(tmp_path / "r.pdf"),
                 "--peak", "9.3kG:5%", "--duration", "4.74ms:15%", "--quiet"])
    err = capsys.readouterr().err
    assert code == 0 and "from a library" not in err and "Glyph" not in err, err
    assert "Recording: \\u6d4b\\u8bd5.csv" in " ".join(_text(tmp_path / "r.pdf").split())


@pytest.mark.parametrize("command", ["fill", "accept"])
def test_a_pdf_in_another_folder_than_its_workbook_is_published_after_it(
        fired, command, tmp_path, capsys):
    """A PDF in another folder than its workbook (accept's default workbook is beside the
    shot) is written: the workbook's publication first, then the PDF's in its own folder (it
    was a ValueError's traceback once the fill had run). Beside each other they are published
    together."""
    folder, shot, rec = fired
    (tmp_path / "w").mkdir()
    (tmp_path / "p").mkdir()
    out, pdf = tmp_path / "w" / "r.xlsx", tmp_path / "p" / "r.pdf"
    argv = {"fill": ["fill", str(shot), "--only", "summary"],
            "accept": ["accept", str(shot), str(rec), "--peak", "9.3kG:5%"]}[command]
    code = main([*argv, "-o", str(out), "--pdf", str(pdf), "--quiet"])
    assert code == 0, capsys.readouterr().err
    assert [p.name for p in (tmp_path / "w").iterdir()] == ["r.xlsx"]
    assert [p.name for p in (tmp_path / "p").iterdir()] == ["r.pdf"]
    assert pdf.read_bytes()[:4] == b"%PDF"


def test_a_later_file_that_cannot_be_published_says_the_first_was(tmp_path):
    """When the PDF's publication fails after the workbook's was committed (its name taken
    meanwhile by another command), the one line says the workbook was written; the PDF's
    temp file is gone and the other command's file untouched."""
    from airgun_xl.transaction import Publication, commit_after, for_file

    (tmp_path / "w").mkdir()
    (tmp_path / "p").mkdir()
    pub = Publication()
    pub.stage(tmp_path / "w" / "r.xlsx").write_bytes(b"workbook")
    later = for_file(pub, tmp_path / "p" / "r.pdf")
    assert later is not pub and for_file(pub, tmp_path / "w" / "r.pdf") is pub
    later.stage(tmp_path / "p" / "r.pdf").write_bytes(b"pdf")
    pub.commit()
    (tmp_path / "p" / "r.pdf").write_bytes(b"another command's")
    with pytest.raises(airgun_xl.OutputError) as caught:
        commit_after(pub, later)
    assert str(caught.value).endswith(f"; {tmp_path / 'w' / 'r.xlsx'} was written")
    assert (tmp_path / "w" / "r.xlsx").read_bytes() == b"workbook"
    assert [p.name for p in (tmp_path / "p").iterdir()] == ["r.pdf"]
    assert (tmp_path / "p" / "r.pdf").read_bytes() == b"another command's"


def test_one_folder_named_two_ways_is_one_folder(tmp_path, monkeypatch):
    """``-o w/r.xlsx --pdf /abs/w/r.pdf`` (and a symlinked folder) name one folder: both are
    published."""
    (tmp_path / "w").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "w", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    assert main(["fill", str(TEMPLATE), "-o", "w/r.xlsx", "--pdf", str(tmp_path / "link" / "r.pdf"),
                 "--only", "summary", "--quiet"]) == 0
    assert sorted(p.name for p in (tmp_path / "w").iterdir()) == ["r.pdf", "r.xlsx"]


def test_accepts_workbook_and_pdf_are_replaced_together_or_not_at_all(fired, tmp_path,
                                                                       monkeypatch):
    """With --force, a verdict workbook that fails to be written leaves the PDF and the
    workbook the user had as they were (the PDF was published first, then removed: the
    user's earlier PDF was lost); a run that succeeds replaces both."""
    folder, shot, rec = fired
    out, pdf = tmp_path / "v.xlsx", tmp_path / "v.pdf"
    out.write_bytes(b"the user's workbook")
    pdf.write_bytes(b"the user's pdf")
    import airgun_xl.reports.acceptance as acceptance

    real = acceptance.write_acceptance

    def failing(*args, **kwargs):
        real(*args, **kwargs)  # staged whole, then the disk fills
        raise airgun_xl.OutputError("v.xlsx: cannot be written (No space left on device)")

    monkeypatch.setattr(acceptance, "write_acceptance", failing)
    with pytest.raises(airgun_xl.OutputError, match="No space left"):
        airgun_xl.accept(shot, rec, peak="9.3kG:5%", output=out, pdf=pdf, force=True)
    assert out.read_bytes() == b"the user's workbook" and pdf.read_bytes() == b"the user's pdf"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.pdf", "v.xlsx"]  # no temp left
    monkeypatch.setattr(acceptance, "write_acceptance", real)
    done = airgun_xl.accept(shot, rec, peak="9.3kG:5%", output=out, pdf=pdf, force=True)
    assert done.files == (out, pdf)
    assert out.read_bytes()[:2] == b"PK" and pdf.read_bytes()[:4] == b"%PDF"
