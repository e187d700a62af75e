"""Issue 44: sweep as a function (airgun_xl.app.sweep.run) and as the Python API
(airgun_xl.sweep), to a DataFrame, driven without the CLI.

The batch kernel is the single-shot kernel run in lanes (tests/test_batch_lanes.py holds
them equal bit for bit), so a grid's peaks equal single runs' exactly; a Monte Carlo's spread
is numpy's over the frame's peaks (its own computation, to 1e-12 relative: summation order)."""
import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.app.sweep import SweepRequest, run
from airgun_xl.cli import main
from airgun_xl.engine.summary import summarize
from airgun_xl.errors import OptionError


def test_a_grid_to_a_frame_holds_each_shots_own_run():
    outcome = airgun_xl.sweep(TEMPLATE, "A28=150:250:3")
    frame = outcome.to_frame()
    assert list(frame.columns) == ["A28", "peak_kg", "time_of_peak", "filtered_peak_kg",
                                   "pulse_duration", "max_crush", "diverged", "invalid",
                                   "warnings"]
    assert frame["A28"].tolist() == [150.0, 200.0, 250.0]
    shot = airgun_xl.load(TEMPLATE)
    for v, peak, duration in zip(frame["A28"], frame["peak_kg"], frame["pulse_duration"],
                                 strict=True):
        alone = shot.with_params(v31=v, v32=v, v33=v).run()
        assert peak == alone.peak_kg
        assert duration == summarize(alone).pulse_duration
    assert not frame["diverged"].any() and not frame["invalid"].any()
    # 250 m/s is past the macro's crush-factor fit: that shot's warning, and the outcome's
    assert frame["warnings"][2] and frame["warnings"][2][0].startswith("A28 ")
    assert outcome.warnings == ("1 of 3 shots have warnings, naming A28 (1 shots): see the "
                                "warnings column of to_frame()",)
    assert outcome.kind == "grid" and outcome.seed is None and outcome.files == ()


def test_a_monte_carlo_repeats_from_its_seed_and_its_spread_is_the_frames():
    first = airgun_xl.sweep(TEMPLATE, mc=64, sd=["E40=3%"], seed=7)
    again = airgun_xl.sweep(TEMPLATE, mc="64", sd="E40=3%", seed=7)
    a, b = first.to_frame(), again.to_frame()
    assert np.array_equal(a["E40"], b["E40"]) and np.array_equal(a["peak_kg"], b["peak_kg"])
    peaks = a["peak_kg"].to_numpy()
    assert first.stats["mean"] == pytest.approx(peaks.mean(), rel=1e-12)
    assert first.stats["sd"] == pytest.approx(peaks.std(ddof=1), rel=1e-12)
    assert first.stats["n"] == 64 and first.kind == "montecarlo" and first.seed == 7
    # the draws spread E40 by about 3 % (64 draws: the sd's own 95 % band is +-18 %)
    assert 0.82 * 0.03 < np.std(a["E40"], ddof=1) / 2.703e7 < 1.18 * 0.03


def test_the_workbook_written_holds_the_frames_figures(tmp_path, capsys):
    out = tmp_path / "s.xlsx"
    outcome = run(SweepRequest(shot=TEMPLATE, vary=("A28=150:250:3",), output=out))
    assert outcome.files == (out,) and out.is_file()
    assert outcome.warnings[0].endswith(f"see the Warnings column and sheet of {out}")
    book = openpyxl.load_workbook(out, read_only=True)
    rows = list(book["Sweep"].iter_rows(min_row=2, max_col=2, values_only=True))
    book.close()
    assert [r[1] for r in rows] == outcome.to_frame()["peak_kg"].tolist()
    # the command prints the outcome
    assert main(["sweep", str(TEMPLATE), "--vary", "A28=150:250:3", "-o",
                 str(tmp_path / "c.xlsx")]) == 0
    frame = outcome.to_frame()
    assert (f"  peak from {frame['peak_kg'].min():.4f} to {frame['peak_kg'].max():.4f} kG "
            "over the grid") in capsys.readouterr().out


#: (keywords, the API's line, the command line's arguments, its line): the API names the
#: keyword, the command its flag, in one line each, and neither writes anything.
BAD = [
    ({"vary": "A99=1:2:3"}, "vary: found 'A99'", ["--vary", "A99=1:2:3"], "--vary: found 'A99'"),
    ({"vary": "A28=1:2:0"}, "vary: found 'A28=1:2:0'", ["--vary", "A28=1:2:0"],
     "--vary: found 'A28=1:2:0'"),
    ({"mc": 10}, "mc: found 10 without sd, expected the spreads of the inputs to draw (sd "
     "CELL=SD[%])", ["--mc", "10"], "--mc: found 10 without --sd, expected the spreads of the "
     "inputs to draw (--sd CELL=SD[%])"),
    ({"mc": 10, "sobol": 8, "sd": "E40=3%"}, "sobol: found it with mc, expected one or the other",
     ["--mc", "10", "--sobol", "8", "--sd", "E40=3%"],
     "--sobol: found it with --mc, expected one or the other"),
    ({}, "vary: found none, expected CELL=LO:HI:N (or mc N with sd)", [],
     "--vary: found none, expected CELL=LO:HI:N (or --mc N with --sd)"),
    ({"mc": 1}, "mc: found 1, expected a number of shots from 2 to 10,000,000",
     ["--mc", "1"], "--mc: found '1', expected a number of shots from 2 to 10,000,000"),
    ({"sd": ["E40=3%", "E40=5%"], "mc": 8}, "sd: found E40 twice",
     ["--sd", "E40=3%", "--sd", "E40=5%", "--mc", "8"], "--sd: found E40 twice"),
    ({"seed": -1, "mc": 8, "sd": "E40=3%"}, "seed: found -1, expected a whole number from 0",
     ["--seed", "-1", "--mc", "8", "--sd", "E40=3%"],
     "--seed: found '-1', expected a whole number from 0"),
    ({"mc": "²", "sd": "E40=3%"}, "mc: found '²', expected a number of shots", ["--mc", "²",
     "--sd", "E40=3%"], "--mc: found '²', expected a number of shots"),
    ({"seed": "9" * 5000, "mc": 8, "sd": "E40=3%"}, "seed: found '99999",
     ["--seed", "9" * 5000, "--mc", "8", "--sd", "E40=3%"], "--seed: found '99999"),
    ({"workers": "two", "vary": "A28=1:2:2"}, "workers: found 'two', expected a whole number",
     ["--workers", "two", "--vary", "A28=1:2:2"], "--workers: found 'two', expected a whole "
     "number"),
]


@pytest.mark.parametrize("given, said, argv, flagged", BAD, ids=[b[1][:24] for b in BAD])
def test_bad_keywords_are_one_line_naming_the_option_and_write_nothing(given, said, argv,
                                                                       flagged, tmp_path,
                                                                       capsys):
    with pytest.raises(OptionError) as caught:
        airgun_xl.sweep(TEMPLATE, output=tmp_path / "s.xlsx", **given)
    assert str(caught.value).startswith(said) and "\n" not in str(caught.value)
    assert main(["sweep", str(TEMPLATE), "-o", str(tmp_path / "c.xlsx"), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"airgun-xl: error: {flagged}") and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []
