"""Issue 44 (property tests): the Python API fed random input. The same text given to a
command's option and to the function's keyword is read the same or refused in the same
words (one grammar, one place); any keyword of any function given random text gives an
outcome or one AirgunXlError line, never another exception, and writes nothing."""
import math

import pytest
from conftest import TEMPLATE
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.errors import AirgunXlError

RECORDING = TEMPLATE.with_name("shot_a_recording.csv")

QUANTITY = st.one_of(st.text(max_size=14), st.sampled_from([
    "12kG:10%", "9.5kG:10%", "12KG", "11750g:-10%,+20%", "1.2e5m/s^2:5%", "12 kG : 10 %",
    "12kG:150%", ":10%", "12kG:", "-5kG:10%", "1e999kG:10%", "nan", "12", "9.5kg:10%",
    "5ms:10%", "4500us:15%", "0.005s:10%", "5:10%", "5ms", "0ms:10%", "240m/s:10%"]))


def _cli(option, text, tmp_path, capsys):
    code = main(["accept", str(TEMPLATE), str(RECORDING), "--sign", "-1",
                 f"--{option.replace('_', '-')}={text}", "-o", str(tmp_path / "v.xlsx"),
                 "--force"])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(option=st.sampled_from(["peak", "duration", "velocity_change"]), text=QUANTITY)
def test_an_option_and_its_keyword_read_the_same_text_alike(option, text, tmp_path, capsys):
    code, out, err = _cli(option, text, tmp_path, capsys)
    try:
        outcome = airgun_xl.accept(TEMPLATE, RECORDING, sign=-1, **{option: text})
    except AirgunXlError as exc:
        assert code == 2, (code, err)
        assert err == f"airgun-xl: error: {exc}\n"
        return
    assert code in (0, 3), err
    for c in outcome.criteria:  # the command printed the function's figures (and U, k = 2)
        u = f" ± {c.expanded:.2g}" if math.isfinite(c.expanded) else ""
        assert f"{c.word}  {c.name}: {c.value:.5g}{u} {c.unit}" in out


NOISE = st.one_of(st.text(max_size=10), st.integers(-10, 10**6),
                  st.floats(allow_nan=True, allow_infinity=True), st.none(),
                  st.sampled_from(["A28=150:250:3", "E40=3%", "A28", "1000", "none", "auto",
                                   "xcorr", "-1", "1e-300"]))

CALLS = {
    "srs": (lambda **kw: airgun_xl.srs(TEMPLATE, **kw), ("q", "cfc", "lo", "hi")),
    "sweep": (lambda **kw: airgun_xl.sweep(TEMPLATE, **kw), ("vary", "sd", "mc", "seed")),
    "accept": (lambda **kw: airgun_xl.accept(TEMPLATE, RECORDING, sign=-1, peak="12kG:10%",
                                             **kw),
               ("duration", "corridor", "shape", "time_slack", "cfc", "srs_q", "placement",
                "pdf", "reproducible")),
    "compare_measured": (lambda **kw: airgun_xl.compare_measured(TEMPLATE, RECORDING, **kw),
                         ("align", "anti_alias", "cfc", "sign")),
    "design": (lambda **kw: airgun_xl.design(TEMPLATE, **kw),
               ("target_peak", "vary", "range", "confidence")),
}


@settings(max_examples=120, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_any_keyword_given_random_input_gives_an_outcome_or_one_line(data, tmp_path,
                                                                      monkeypatch):
    monkeypatch.chdir(tmp_path)
    name = data.draw(st.sampled_from(sorted(CALLS)))
    call, keywords = CALLS[name]
    given = data.draw(st.dictionaries(st.sampled_from(keywords), NOISE, max_size=2))
    if name == "sweep" and "mc" in given and isinstance(given["mc"], int):
        given["mc"] = min(given["mc"], 50)  # a study's size, not its reading, is the cost
    try:
        outcome = call(**given)
    except AirgunXlError as exc:
        text = str(exc)
        assert text and "\n" not in text and len(text) < 600, text
    else:
        assert outcome.files == ()
    assert list(tmp_path.iterdir()) == []  # no output asked: nothing written


@pytest.mark.parametrize("sign", [0, 2, -0.5, float("nan")])
def test_a_sign_that_is_not_one_is_refused_by_every_function_alike(sign):
    refusals = set()
    for call in (lambda: airgun_xl.accept(TEMPLATE, RECORDING, sign=sign, peak="12kG"),
                 lambda: airgun_xl.compare_measured(TEMPLATE, RECORDING, sign=sign),
                 lambda: airgun_xl.calibrate(TEMPLATE, RECORDING, sign=sign, fit="E40")):
        with pytest.raises(AirgunXlError) as caught:
            call()
        refusals.add(str(caught.value))
    assert refusals == {f"sign: found {sign!r}, expected 1 or -1"}  # the keyword, as given


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(given=st.dictionaries(st.sampled_from(["sd", "confidence", "shots", "lot", "seed",
                                              "sign", "cfc", "vary", "gun", "step"]),
                             NOISE,
                             max_size=2))
def test_next_given_random_input_writes_what_it_says_or_nothing(given):
    """airgun_xl.next_shot with random keywords: an outcome whose files are what was
    written (the next workbook; the archive's records), or one line and nothing written or
    recorded at all."""
    import tempfile
    from pathlib import Path

    keywords = {"sd": ["A28=1.5%"], "shots": 100, "lot": "LOT-P", "sign": -1,
                "peak": "9.5kG:10%", "duration": "5ms:15%", **given}
    if isinstance(keywords["shots"], int) and not isinstance(keywords["shots"], bool):
        keywords["shots"] = min(keywords["shots"], 200)  # a study's size, not its reading
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        try:
            outcome = airgun_xl.next_shot(TEMPLATE, RECORDING, archive=folder / "arch",
                                          new_lot=True, output=folder / "next.xlsx",
                                          **keywords)
        except AirgunXlError as exc:
            text = str(exc)
            assert text and "\n" not in text and len(text) < 600, text
            assert list(folder.iterdir()) == []
        else:
            assert outcome.files == (folder / "next.xlsx",) and outcome.files[0].is_file()
            assert sorted(p.name for p in folder.iterdir()) == ["arch", "next.xlsx"]
