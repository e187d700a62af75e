"""Issue 10: a long fill shows a progress bar on a terminal, none in logs, and says what a big
run will cost before it starts."""
import io

import openpyxl
from conftest import TEMPLATE

from airgun_xl.app.fill import notices, sidecar_bytes
from airgun_xl.cli import main, progress
from airgun_xl.limits import fill_bytes


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_bar_moves_through_the_stages_and_clears_its_line():
    stream = Terminal()
    bar = progress.Progress(10.0, stream)
    assert bar.enabled
    for stage in progress.STAGES:
        bar(stage)
    bar.close()
    text = stream.getvalue()
    assert all(f"{stage} (" in text for stage in progress.STAGES)
    assert text.endswith("\r\x1b[K") and not progress.ACTIVE


def test_no_bar_for_a_short_fill_or_a_log():
    assert not progress.Progress(0.5, Terminal()).enabled  # under SHOW_AFTER_SECONDS
    assert not progress.Progress(100.0, io.StringIO()).enabled  # not a terminal


def test_fill_on_a_terminal_shows_the_bar_and_keeps_messages_whole(tmp_path, monkeypatch):
    """The template's 12,002 rows, counted as a long fill: the bar is drawn on stderr, and a
    warning printed meanwhile starts on a cleared line."""
    stream = Terminal()
    monkeypatch.setattr("sys.stderr", stream)
    monkeypatch.setattr(progress, "SECONDS_PER_ROW", 1.0)
    shot = tmp_path / "shot.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    wb["Sheet1"]["E34"] = 7000  # a fractional sample rate: a warning during the run
    wb.save(shot)
    assert main(["fill", str(shot), "-o", str(tmp_path / "o.xlsx"), "--only", "summary"]) == 0
    text = stream.getvalue()
    assert "\r[" in text and "] " in text and "running (" in text
    assert "\r\x1b[Kairgun-xl: warning: E34 (Filter Frequency)" in text
    assert text.endswith("\r\x1b[K")


def test_log_gets_no_bar(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(progress, "SECONDS_PER_ROW", 1.0)
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--only",
                 "summary"]) == 0
    assert "\r" not in capsys.readouterr().err


def test_notices_for_memory_past_1_gb_and_a_sidecar_past_100_mb(tmp_path):
    """The thresholds against the estimates they use: 5 ns shot A (1.2M rows, 8 series
    tracked) writes a sidecar of up to 163 MB; 5M rows need 1.2 GB (limits.fill_bytes)."""
    track = frozenset(range(8))
    assert sidecar_bytes(1_200_002, 8) > 100e6 > sidecar_bytes(500_000, 8)
    said = notices(1_200_002, track, tmp_path / "o.history.parquet")
    assert said == ["the full history goes to " + str(tmp_path / "o.history.parquet")
                    + ", up to 163 MB"]
    assert fill_bytes(5_000_000, 8) > 1e9
    said = notices(5_000_000, track, None)
    assert said == ["5,000,000 rows: this run needs about 1.2 GB of memory"]
    assert notices(12_002, track, tmp_path / "s.parquet") == []


def test_fill_says_the_notice_before_it_starts(tmp_path, capsys):
    """A 5 ns run of shot A, cut to 0.6 ms (120k rows) with a sidecar always written: no
    notice (12 MB); the same at 6 ms gives it, before the summary lines."""
    shot = tmp_path / "shot.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    wb["Sheet1"]["E2"] = 5e-9
    wb["Sheet1"]["E6"] = 6e-4
    wb.save(shot)
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot), "-o", str(out), "--only", "summary", "--sidecar",
                 "always"]) == 0
    assert "note:" not in capsys.readouterr().err
    wb["Sheet1"]["E6"] = 6e-3
    wb.save(shot)
    assert main(["fill", str(shot), "-o", str(out), "--only", "summary", "--sidecar",
                 "always", "--force"]) == 0
    err = capsys.readouterr().err
    assert "airgun-xl: note: the full history goes to" in err and "up to 163 MB" in err
