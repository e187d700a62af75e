"""Issue 48 (second part): the view's scatter, filters, compare and laws pages, and a shot's
verdicts, in Debian's Chromium, on a small lab's archive.

The lab: shot A filled into the archive (shot1, the report's law), fired on a lot 10 % stronger
than the report's law and put through ``next`` (its verdict FAIL, law LOT-A@1, a proposal);
the proposed workbook filled with LOT-A@1 (shot1.next), fired and put through ``next`` (PASS,
LOT-A@2); the second proposal filled with LOT-A@2 (shot3), fired and judged by ``accept`` with
a half-sine's corridor. Beside them, records as a hostile hand would leave them: a law whose
fields are a script, a verdict of shot3 whose criterion is one (and no workbook's SHA-256, as
an older record), a verdict of another workbook named shot3, and a law folder that is a link
to a folder outside the archive.

What is checked against the archive's own records (read here with the tool's readers): every
point of the scatter, every row a filter keeps, every input a compare lists as differing, every
law version's runs, the chain's verdicts and P(PASS), a verdict's criteria and the peak's
limits drawn.
"""
import csv
import io
import json
import shutil

import pytest
from conftest import TEMPLATE, write_trace_csv
from serve_helpers import get, screenshot, serving

import airgun_xl
from airgun_xl.app.archive import shown_figure
from airgun_xl.app.lot_chain import chain, expected_text, knobs_text, measured_text
from airgun_xl.app.next_shot import prediction_record
from airgun_xl.archive.lots import proposals
from airgun_xl.crush_law import LEGACY_LAW
from airgun_xl.studies.calibrate import synthetic_measurement

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")
pytestmark = pytest.mark.slow  # a lab's two shots through next, a server, a browser
HOSTILE = "=HYPERLINK(\"http://x\")<script>window.pwned=1</script>"
SPEC = {"peak": "8.5kG:5%", "duration": "4.5ms:15%"}


def _fire(workbook, recording, seed):
    """The lab fires ``workbook`` on a lot 10 % stronger than the report's law."""
    p = airgun_xl.load(workbook).params.replace(crush_law=LEGACY_LAW.scaled(1.10))
    write_trace_csv(recording, synthetic_measurement(p, dt=1 / 51_200, seed=seed))


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    work = tmp_path_factory.mktemp("lab")
    root = work / "arch"
    shot1 = work / "shot1.xlsx"
    shot1.write_bytes(TEMPLATE.read_bytes())
    airgun_xl.fill(shot1, output=work / "out1.xlsx", archive=root)
    _fire(shot1, work / "rec1.csv", 3)
    first = airgun_xl.next_shot(shot1, work / "rec1.csv", archive=root, lot="LOT-A",
                                new_lot=True, sd=["A28=1.5%"], shots=100, **SPEC)
    airgun_xl.fill(first.output, output=work / "out2.xlsx", archive=root, crush_law="LOT-A@1")
    _fire(first.output, work / "rec2.csv", 4)
    second = airgun_xl.next_shot(first.output, work / "rec2.csv", archive=root, lot="LOT-A",
                                 sd=["A28=1.5%"], shots=100, output=work / "shot3.xlsx",
                                 **SPEC)
    airgun_xl.fill(second.output, output=work / "out3.xlsx", archive=root,
                   crush_law="LOT-A@2")
    _fire(second.output, work / "rec3.csv", 5)  # judged with a corridor: its verdict FAIL
    accepted = airgun_xl.accept(second.output, work / "rec3.csv", archive=root,
                                output=work / "verdict3.xlsx", shape="half-sine",
                                corridor="20%", **SPEC)
    assert accepted.word == "FAIL" and accepted.archived.name == "v0001.json"
    # a law calibrate keeps, with its nodes' intervals (a lot 5 % stronger in yield stress)
    p = airgun_xl.load(TEMPLATE).params
    write_trace_csv(work / "cal.csv", synthetic_measurement(p.replace(sigmay=p.sigmay * 1.05),
                                                            seed=5))
    calibrated = airgun_xl.calibrate(TEMPLATE, work / "cal.csv", cfc=1000, archive=root,
                                     name="CAL-1")
    assert calibrated.stored == "CAL-1@1"
    # hostile records: a law and a verdict whose texts are a script, a law folder that links
    # out of the archive
    law = json.loads((root / ".laws" / "LOT-A" / "v0001.json").read_text())
    law.pop("proposal")  # a law of its own, not one next made for LOT-A's proposal 1
    (root / ".laws" / "EVIL").mkdir()
    (root / ".laws" / "EVIL" / "v0001.json").write_text(json.dumps(
        {**law, "shots": [{"workbook": HOSTILE}], "created": HOSTILE}))
    outside = work / "outside"
    outside.mkdir()
    (outside / "v0001.json").write_text(json.dumps({**law, "created": "OUTSIDE-THE-ARCHIVE"}))
    (root / ".laws" / "LINKED").symlink_to(outside, target_is_directory=True)
    verdict = json.loads((root / ".verdicts" / "LOT-A.shot1" / "v0001.json").read_text())
    (root / ".verdicts" / "shot3" / "v0002.json").write_text(json.dumps(
        {**verdict, "shot": "shot3", "shot_sha256": None,  # as a record before they kept it
         "criteria": [{**verdict["criteria"][0], "name": HOSTILE}],
         "trace": {"time_ms": [HOSTILE, 0.1, 0.2], "kg": [1.0, HOSTILE, 3.0], "onset_ms": None,
                   "upper_kg": None, "lower_kg": None, "samples": 3, "thinned": HOSTILE}}))
    # a verdict of another workbook named shot3 (another version's): not shot3@1's
    (root / ".verdicts" / "shot3" / "v0003.json").write_text(json.dumps(
        {**verdict, "shot": "shot3", "shot_sha256": "0" * 64, "verdict": "PASS",
         "criteria": [{**verdict["criteria"][0], "name": "ANOTHER-WORKBOOK"}]}))
    return root


@pytest.fixture(scope="module")
def server(lab):
    with serving(lab) as url:
        yield url


def _summary(lab, shot):
    return json.loads((lab / shot / "v0001" / "summary.json").read_text())


def _inputs(lab, shot):
    return {p["cell"]: p["value"] for p in
            json.loads((lab / shot / "v0001" / "params.json").read_text())}


def _csv(server, query):
    status, _h, body = get(f"{server}/shots.csv?{query}")
    assert status == 200
    return list(csv.DictReader(io.StringIO(body.decode())))


def test_filters_by_lot_verdict_and_any_input_a_limit_within(server, lab):
    """Each filter keeps exactly the runs its field selects; a value on a limit is within."""
    def shots(query):
        return [r["shot"] for r in _csv(server, query + "&sort=id")]

    assert shots("") == ["shot1", "shot1.next", "shot3"]
    assert shots("lot=LOT-A") == ["shot1.next", "shot3"]
    assert shots("lot=(none)") == ["shot1"]
    assert shots("verdict=PASS") == ["shot1.next"]
    assert shots("verdict=FAIL") == ["shot1", "shot3"]
    assert shots("verdict=none") == []
    v3 = _inputs(lab, "shot3")["A28"]
    # each run's A28 read from its params.json (two proposals may set the same velocity)
    a28 = {s: _inputs(lab, s)["A28"] for s in ("shot1", "shot1.next", "shot3")}
    on = [s for s, v in a28.items() if v == v3]
    assert "shot3" in on
    assert shots(f"input=A28&input_min={v3!r}&input_max={v3!r}") == on  # on both limits
    assert shots(f"input=A28&input_min={v3 * (1 + 1e-12)!r}") == [
        s for s, v in a28.items() if v > v3]
    # an input the index does not hold (read from each params.json): E43, zeta, 0.02 in all
    assert shots("input=E43&input_min=0.02&input_max=0.02") == ["shot1", "shot1.next", "shot3"]
    assert shots("input=E43&input_max=0.019") == []
    # a limit given in full is kept in full by the page's own links (sort, pages, CSV)
    status, _h, body = get(f"{server}/shots?input=A28&input_min={v3!r}")
    assert status == 200 and f"input_min={v3!r}".encode() in body
    assert b"input_min=228.943&" not in body and b"input_min=228.943\"" not in body
    rows = _csv(server, "lot=LOT-A")
    assert [r["warning texts"] for r in rows] == ["; ".join(_summary(lab, s)["warnings"])
                                                  for s in ("shot1.next", "shot3")]
    assert [r["lot"] for r in rows] == ["LOT-A", "LOT-A"]
    assert [r["recorded verdict"] for r in rows] == ["PASS", "FAIL"]


def test_the_scatter_draws_any_figure_against_any_input_coloured_and_on_log_axes(page, server,
                                                                                 lab):
    page.goto(f"{server}/shots")
    page.wait_for_selector("#scatter[data-drawn]")
    screenshot(page, "serve-scatter")
    data = json.loads(page.text_content("#scatter-data"))
    assert [(s["name"], s["points"]) for s in data["series"]] == [("LOT-A", 2), ("none", 1)]
    assert page.get_attribute("#scatter", "data-series") == "2"
    # the pulse duration [ms] against A28, coloured by recorded verdict, on a log y axis
    page.select_option("select[name=y]", "pulse_duration")
    page.select_option("select[name=colour]", "verdict")
    page.check("input[name=logy]")
    page.click("#filters button")
    page.wait_for_selector("#scatter[data-drawn]")
    assert "y=pulse_duration" in page.url and "colour=verdict" in page.url \
        and "logy=1" in page.url
    page.goto(page.url)  # the view survives a reload by its URL
    page.wait_for_selector("#scatter[data-drawn]")
    assert page.input_value("select[name=y]") == "pulse_duration"
    assert page.is_checked("input[name=logy]")
    data = json.loads(page.text_content("#scatter-data"))
    assert data["logy"] and data["y_label"] == "pulse duration [ms]"
    drawn = {}
    for s in data["series"]:
        for x, y in zip(data["x"], s["y"], strict=True):
            if y is not None:
                drawn.setdefault(s["name"], []).append((x, y))
    expected = {}
    for shot, verdict in (("shot1", "FAIL"), ("shot1.next", "PASS"), ("shot3", "FAIL")):
        point = (float(f"{_inputs(lab, shot)['A28']:.6g}"),
                 float(f"{_summary(lab, shot)['pulse_duration'] * 1e3:.6g}"))
        expected.setdefault(verdict, []).append(point)
    assert {k: sorted(v) for k, v in drawn.items()} == {k: sorted(v) for k, v in
                                                        expected.items()}
    # on a log axis, a value that is not positive is left out and said: A27 is 0 in all
    page.goto(f"{server}/shots?x=A27&logx=1")
    page.wait_for_selector("#scatter[data-drawn]")
    assert page.text_content("#scatter-note").startswith("3 run(s) not drawn")


def test_compare_lists_what_differs_and_its_set_changes_in_place(page, server, lab):
    page.goto(f"{server}/shots?sort=id")
    page.wait_for_selector("#scatter[data-drawn]")
    page.check("#shots tbody tr:nth-child(1) input[name=id]")
    page.check("#shots tbody tr:nth-child(3) input[name=id]")
    page.click("#compare-selected")
    page.wait_for_selector("#overlay[data-drawn]")
    screenshot(page, "serve-compare")
    assert page.url == f"{server}/compare?id=1&id=3"
    assert page.get_attribute("#overlay", "data-series") == "2"
    differ = page.eval_on_selector_all(
        "#compared tr.input", "rows => rows.map(r => [...r.cells].map(c => c.textContent))")
    one, three = _inputs(lab, "shot1"), _inputs(lab, "shot3")
    cells = sorted(c for c in one if one[c] != three[c])
    assert cells == ["A28", "A29", "A30"]  # the proposal's speed, set in the three cells
    assert [row[0].split(" ")[0] for row in differ[:3]] == cells
    assert [float(row[1]) for row in differ[:3]] == [one[c] for c in cells]
    assert [float(row[2]) for row in differ[:3]] == [three[c] for c in cells]
    assert differ[3] == ["crush law", "legacy (Eq. 8)", "fitted (LOT-A@2)"]
    figures = {row[0]: row[1:] for row in page.eval_on_selector_all(
        "#compared tr.figure", "rows => rows.map(r => [...r.cells].map(c => c.textContent))")}
    for shot, column in (("shot1", 0), ("shot3", 1)):
        peak = _summary(lab, shot)["peak_kg"]
        assert figures["Peak acceleration (raw)"][column] == shown_figure("peak_kg", peak)[1]
    # the set changed in place: one removed, another added, and a reload keeps it
    page.click("#compared th:nth-child(2) a.remove")
    page.wait_for_selector("#overlay[data-drawn]")
    assert page.url == f"{server}/compare?id=3"
    page.select_option("#add", "2")
    page.click("#compare-set button")
    page.wait_for_selector("#overlay[data-drawn]")
    assert page.url == f"{server}/compare?id=3&id=2"
    page.goto(page.url)
    page.wait_for_selector("#overlay[data-drawn]")
    heads = page.eval_on_selector_all("#compared th a:not(.remove)",
                                      "links => links.map(a => a.textContent)")
    assert heads == ["shot3@1", "shot1.next@1"]


def test_the_laws_page_holds_each_version_its_runs_the_chain_and_the_outcomes(page, server,
                                                                              lab):
    page.goto(f"{server}/laws")
    page.wait_for_selector(".law-chart[data-drawn]")
    screenshot(page, "serve-laws")
    assert page.evaluate("window.pwned") is None
    sections = page.eval_on_selector_all("section.lot h2", "hs => hs.map(h => h.textContent)")
    assert sections == ["CAL-1", "EVIL", "LOT-A"]  # the link out of the archive: not followed
    # calibrate's law: each node with its interval, as the record keeps them
    record = json.loads((lab / ".laws" / "CAL-1" / "v0001.json").read_text())
    nodes = page.locator("section.lot", has_text="CAL-1").first.locator("td.pinned")
    said = nodes.inner_text()
    assert len(record["intervals"]) == 7
    for n in record["intervals"]:
        assert (f"{n['velocity']:.1f} m/s: {n['value']:.4f} ({n['low']:.4f} to "
                f"{n['high']:.4f})") in said
    assert said.count("weakly pinned") == sum(n["weak"] for n in record["intervals"])
    cal = page.locator("section.lot", has_text="CAL-1").first
    assert cal.locator(".law-chart").get_attribute("data-series") == "3"
    drawn = json.loads(cal.locator(".law-chart + script").text_content())
    assert drawn["names"] == ["CAL-1@1", "CAL-1@1 nodes, 95 % low", "CAL-1@1 nodes, 95 % high"]
    for k, end in ((1, "low"), (2, "high")):
        points = {x: y for x, y in zip(drawn["x"], drawn["y"][k], strict=True) if y is not None}
        assert points == {float(f"{n['velocity']:.6g}"): float(f"{n[end]:.6g}")
                          for n in record["intervals"]}
    assert "OUTSIDE-THE-ARCHIVE" not in page.content()
    lot = page.locator("section.lot", has_text="LOT-A").last
    assert lot.locator(".law-chart").get_attribute("data-series") == "2"
    versions = lot.locator("table.versions tr").all_text_contents()[1:]
    assert versions[0].startswith("LOT-A@1") and "shot1.next@1" in versions[0]
    assert versions[1].startswith("LOT-A@2") and "shot3@1" in versions[1]
    for (_v, proposal), text in zip(proposals(lab, "LOT-A"), versions, strict=True):
        assert (f"scaled by next: ×{proposal['scale']:.4f} ± {proposal['scale_error']:.4f} "
                "(standard error)") in text
    rows = [r.split("\n") for r in lot.locator("table.chain tr").evaluate_all(
        "rows => rows.slice(1).map(r => [...r.cells].map(c => c.textContent).join('\\n'))")]
    expected = chain(lab, "LOT-A")
    assert [r[2] for r in rows] == [e["verdict"] for e in expected] == ["FAIL", "PASS"]
    assert rows[0][3] == "n/a" and rows[1][3] == f"{expected[1]['predicted_before']:.3f}"
    assert [r[7] for r in rows] == [f"{e['next_A28']:.3f}" for e in expected]
    # what each proposal expected of its shot, what the shot measured, every knob set next
    assert rows[0][4] == "n/a" and rows[1][4] == expected_text(expected[1]["expected_before"])
    assert rows[1][4].startswith("peak ") and " kG (" in rows[1][4]
    assert [r[5] for r in rows] == [measured_text(e["measured"]) for e in expected]
    assert all(r[5].startswith("peak ") for r in rows)
    assert [r[9] for r in rows] == [knobs_text(e) for e in expected]
    assert all(r[9].startswith("A28 ") and "; expected peak " in r[9] for r in rows)
    # each P(PASS) with the warnings its proposal keeps (what it cannot vouch for)
    kept = [record.get("warnings") or [] for _v, record in proposals(lab, "LOT-A")]
    said = lot.locator("table.chain td.warnings").all_inner_texts()
    assert len(said) == len(kept)
    for text, carried in zip(said, kept, strict=True):
        assert (text.strip() == "none") == (not carried)
    for w in {w for ws in kept for w in ws}:  # each said once, on the chain
        assert "\n".join(said).count(w) == 1, w
    record = prediction_record(lab)
    assert page.text_content("#record") == (f"1 shot fired from next's proposals; Brier score "
                                            f"{record.brier:.4f}.")
    evil = page.locator("section.lot", has_text="EVIL")
    assert HOSTILE in evil.text_content()  # a script shown as text


def test_a_shots_page_lists_its_verdicts_and_draws_the_peaks_limits(page, server, lab):
    page.goto(f"{server}/shot/1")
    page.wait_for_selector("#pulse[data-drawn]")
    record = json.loads((lab / ".verdicts" / "LOT-A.shot1" / "v0001.json").read_text())
    assert page.text_content("h3.recorded").startswith("Recorded verdict 1: FAIL")
    table = page.eval_on_selector_all(
        "#recorded-criteria-1 tr", "rows => rows.slice(1).map(r => [...r.cells].map("
        "c => c.textContent))")
    assert [r[0] for r in table] == [c["name"] for c in record["criteria"]]
    assert [r[1] for r in table] == [f"{c['value']:.6g} {c['unit']}" for c in
                                     record["criteria"]]
    assert [r[5] for r in table] == ["PASS" if c["passed"] else "FAIL"
                                     for c in record["criteria"]]
    peak = next(c for c in record["criteria"] if c["name"] == "peak")
    assert peak["unit"] == "kG"
    pulse = json.loads(page.text_content("#pulse-data"))
    assert pulse["band"] == [float(f"{peak['low']:.6g}"), float(f"{peak['high']:.6g}")]
    assert page.get_attribute("#pulse", "data-series") == "3"  # the pulse and two limits
    assert page.locator("#verdict-chart-1").count() == 1  # the record judged, no corridor
    # shot3: its verdict judged a corridor; the record and the limits drawn over the
    # prediction, shifted as the page says; the hostile second verdict's criterion is text
    page.goto(f"{server}/shot/3")
    page.wait_for_selector("#verdict-chart-1[data-drawn]")
    page.locator("h3.recorded").first.scroll_into_view_if_needed()
    page.evaluate("window.scrollBy(0, -20)")
    screenshot(page, "serve-verdict")
    assert page.evaluate("window.pwned") is None
    assert page.text_content("#recorded-criteria-2 tr:nth-child(2) td") == HOSTILE
    # the first verdict is of this very workbook; the second was matched by name, and says
    # so; the third, of another workbook of that name, is not this run's
    said = page.locator("h3.recorded").all_text_contents()
    assert [t.split(":")[0] for t in said] == ["Recorded verdict 1", "Recorded verdict 2"]
    assert page.locator("p.by-name").count() == 1
    assert "ANOTHER-WORKBOOK" not in page.content()
    assert page.get_attribute("#verdict-chart-1", "data-series") == "4"
    trace = json.loads((lab / ".verdicts" / "shot3" / "v0001.json").read_text())["trace"]
    drawn = json.loads(page.locator("#verdict-chart-1 + script").text_content())
    assert drawn["names"] == ["predicted pulse", "record judged", "corridor upper",
                              "corridor lower"]
    shift = _summary(lab, "shot3")["pulse_start"] * 1e3 - trace["onset_ms"]
    assert drawn["shift_ms"] == pytest.approx(shift, abs=1e-5)
    record = {x: y for x, y in zip(drawn["x"], drawn["y"][1], strict=True) if y is not None}
    expected = {float(f"{t + drawn['shift_ms']:.6g}"): k
                for t, k in zip(trace["time_ms"], trace["kg"], strict=True)}
    assert record == expected
    assert max(y for y in drawn["y"][2] if y is not None) == max(
        u for u in trace["upper_kg"] if u is not None)
    # the hostile trace: a text where a number belongs is a gap, its words text
    hostile = json.loads(page.locator("#verdict-chart-2 + script").text_content())
    assert hostile["names"] == ["predicted pulse", "record judged"]
    assert {x: y for x, y in zip(hostile["x"], hostile["y"][1], strict=True)
            if y is not None} == {0.2: 3.0}
    assert HOSTILE in page.locator("#verdict-chart-2 ~ p.note").first.text_content()


def test_the_listing_is_read_once_and_again_when_the_archive_changes(lab, tmp_path,
                                                                     monkeypatch):
    """Entries are read once while the index is unchanged; a new fill is listed at the next
    request, without a restart; past FRESH seconds the index is read again anyway."""
    from airgun_xl.web import listing

    root = tmp_path / "copy"
    shutil.copytree(lab, root, symlinks=True)
    view = listing.Listing(listing.read_only(root))  # as the server opens it
    first = view.snapshot()
    assert view.snapshot() is first
    assert [r["shot"] for r in first.rows] == ["shot1", "shot1.next", "shot3"]
    airgun_xl.fill(TEMPLATE, output=tmp_path / "o.xlsx", archive=root, name="later")
    second = view.snapshot()
    assert [r["shot"] for r in second.rows] == ["shot1", "shot1.next", "shot3", "later"]
    assert all(a is b for a, b in zip(first.rows, second.rows[:3], strict=False))  # kept
    monkeypatch.setattr(listing, "FRESH", 0.0)
    assert view.snapshot() is not second


def test_an_entry_folder_that_links_out_of_the_archive_is_never_read(lab, tmp_path):
    """An index row whose shot folder is a link to a copy of an entry outside the archive
    (its peak made 123.456 kG): the listing names the link and shows no figure of it, its
    page is refused as show refuses it, and nothing of the outside entry reaches a page."""
    import sqlite3

    root = tmp_path / "copy"
    shutil.copytree(lab, root, symlinks=True)
    outside = tmp_path / "outside" / "v0001"
    shutil.copytree(lab / "shot3" / "v0001", outside)
    summary = json.loads((outside / "summary.json").read_text())
    (outside / "summary.json").write_text(json.dumps({**summary, "peak_kg": 123.456}))
    (root / "linked").symlink_to(outside.parent, target_is_directory=True)
    with sqlite3.connect(root / "index.sqlite") as conn:
        row = conn.execute("SELECT * FROM entries WHERE id = 3").fetchone()
        conn.execute("INSERT INTO entries VALUES (?, 'linked', 1, 'linked/v0001', ?, ?, ?, ?, "
                     "?, ?, ?, ?, ?, ?, ?)", (9, *row[4:]))
    with serving(root) as url:
        rows = {r["shot"]: r for r in csv.DictReader(io.StringIO(
            get(f"{url}/shots.csv")[2].decode()))}
        said = rows["linked"]["crush law"]
        assert said.startswith("unreadable: linked@1: ") and said.endswith(
            f"{root / 'linked'} is a link to {outside.parent}, expected the entry's own folder "
            "inside the archive (not followed; see airgun-xl archive verify)")
        assert rows["linked"]["pulse duration [ms]"] == ""
        status, _h, body = get(f"{url}/shot/9")
        assert status == 404 and b"linked is a link to" in body
        for path in ("/shots", "/shots.csv", "/shot/9", "/compare?id=9&id=1", "/laws"):
            assert b"123.456" not in get(url + path)[2], path


def test_while_the_first_listing_is_read_the_pages_say_how_far_and_a_shot_answers(
        lab, monkeypatch):
    """The server reads its listing in the background from its start; a page asked before
    that ends answers at once, 503 with the progress and a reload (its CSV the same in
    words), and a shot's page answers from the index alone. Held open here by an event at
    the second entry, so the test sees the middle of the read, whatever the machine."""
    import threading

    import uvicorn

    from airgun_xl.web import listing
    from airgun_xl.web import server as web

    gate, reached = threading.Event(), threading.Event()
    inputs_gate, inputs_reached = threading.Event(), threading.Event()
    real, real_inputs = listing.entry_row, listing.with_inputs

    def held(entry):
        if entry.id == 2:
            reached.set()
            assert gate.wait(60)
        return real(entry)

    def inputs_held(row, entry):
        if entry.id == 2:
            inputs_reached.set()
            assert inputs_gate.wait(60)
        return real_inputs(row, entry)

    monkeypatch.setattr(listing, "entry_row", held)
    monkeypatch.setattr(listing, "with_inputs", inputs_held)
    app = web.build_app(lab)  # its listing's read starts here
    sock = web.listen("127.0.0.1", 0)
    server = uvicorn.Server(uvicorn.Config(app, log_level="critical", lifespan="off"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    url = f"http://127.0.0.1:{sock.getsockname()[1]}"
    try:
        assert reached.wait(60)
        while not server.started:  # a poll for uvicorn's own flag
            thread.join(0.01)
        status, headers, body = get(f"{url}/shots")
        assert status == 503 and b'http-equiv="refresh" content="1"' in body
        assert b"1 of 3 so far" in body
        status, _h, body = get(f"{url}/shots.csv")
        assert status == 503 and body == b"reading the archive's runs (1 of 3): try again in a " \
                                          b"second\n"
        status, _h, body = get(f"{url}/shot/1")
        assert status == 200 and b"shot1@1" in body
        gate.set()
        app.state.view.listing.snapshot()  # waits for the read to end
        status, _h, body = get(f"{url}/shots")
        assert status == 200 and b"3 of 3 runs" in body
        # then the inputs the index does not hold: a page drawing by one says how far
        assert inputs_reached.wait(60)
        status, _h, body = get(f"{url}/shots?x=E43")
        assert status == 503 and b"reading the archive&#39;s runs&#39; inputs: 1 of 3" in body
        assert get(f"{url}/shots?x=E2")[0] == 200  # an input the index holds: at once
        inputs_gate.set()
        while app.state.view.listing.inputs_progress is not None:  # a poll for the read's end
            thread.join(0.01)
        status, _h, body = get(f"{url}/shots?x=E43")
        assert status == 200 and b"3 of 3 runs" in body
    finally:
        gate.set()
        inputs_gate.set()
        server.should_exit = True
        thread.join(30)
        sock.close()
