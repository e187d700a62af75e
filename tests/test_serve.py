"""Issue 48 (first part): ``airgun-xl serve``, the archive's read-only view, tested in a real
browser: Debian's Chromium driven by Playwright (its executable path given, so no browser is
downloaded), against a ``serve`` the test starts, on an archive of three shot A fills at
230, 243.5 and 250 m/s, one of whose index rows is hostile (its shot name a script).

The shots page draws its scatter, filters and sorts by URL (a reload keeps the view), pages on
the server, and its CSV holds the rows shown; a shot's page draws the predicted pulse and lists
its figures with units and its warnings. No page error, no request but to the server, and the
hostile name is text. An archive whose index is on a PostgreSQL server (tests/pg_server.py)
is browsed the same way. Over plain HTTP: POST is 405, a rebinding Host is 400, an id that is not
a number or not in the index is 404, nothing outside the static folder is served, and a port
in use is one line, exit 2."""
import csv
import io
import json
import os
import signal
import sqlite3
import sys

import openpyxl
import pytest
from conftest import TEMPLATE
from serve_helpers import get, screenshot, serving, start, watched

from airgun_xl.archive.laws import store_law
from airgun_xl.cli import main
from airgun_xl.crush_law import LEGACY_LAW

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")
pytestmark = pytest.mark.slow  # servers in processes, a browser
HOSTILE = "=HYPERLINK(\"http://x\")<script>window.pwned=1</script>"
SPEEDS = (230.0, 243.5, 250.0)


def _fill(work, root, speeds, prefix):
    """Shot A filled into ``root`` at each of ``speeds`` (A28), named PREFIX_SPEED."""
    for v in speeds:
        book = openpyxl.load_workbook(TEMPLATE)
        book.active["A28"] = v
        shot = work / f"shot_{v:g}.xlsx"
        book.save(shot)
        assert main(["fill", str(shot), "-o", str(work / f"out_{v:g}.xlsx"), "--archive",
                     str(root), "--name", f"{prefix}_{v:g}"]) == 0


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    """Three fills of shot A (A28 at each speed) archived; the third's index row renamed to
    a script, as a tampered index would hold it."""
    work = tmp_path_factory.mktemp("serve")
    root = work / "archive"
    _fill(work, root, SPEEDS, "shot")
    with sqlite3.connect(root / "index.sqlite") as conn:
        conn.execute("UPDATE entries SET shot = ? WHERE id = 3", (HOSTILE,))
    return root


@pytest.fixture(scope="module")
def server(archive):
    with serving(archive) as url:
        yield url


def test_only_get_from_this_machine_and_nothing_outside_the_archive(server):
    status, headers, body = get(f"{server}/shots")
    assert status == 200 and headers["content-security-policy"].startswith("default-src 'self'")
    assert headers["x-content-type-options"] == "nosniff"
    assert get(f"{server}/shots", "POST")[0] == 405
    assert get(f"{server}/shots", "DELETE")[0] == 405
    assert get(f"{server}/shots", headers={"Host": "attacker.example"})[0] == 400
    assert get(f"{server}/shot/999")[0] == 404
    for path in ("/shot/..%2f..%2findex.sqlite", "/shot/1%2f..", "/static/..%2findex.sqlite",
                 "/static/../../index.sqlite", "/index.sqlite"):
        status, _h, body = get(server + path)
        assert status == 404 and b"SQLite" not in body, path
    # the hostile row's name never reaches a page as markup; a compare names its refusal
    for path in ("/shots", "/shot/3", "/compare?id=1&id=3", "/laws", "/shots?shot=%3Cscript"):
        status, _h, body = get(server + path)
        assert status in (200, 404) and b"<script>window.pwned" not in body, path
    body = get(f"{server}/compare?id=1&id=3")[2].decode()
    said = "row #3: it says =HYPERLINK(&#34;http://x&#34;)&lt;script&gt;"
    assert 'id="refused"' in body and said in body
    # an id that is not a number is no entry (nothing is looked up by it)
    for query in ("id=..%2F..%2Findex.sqlite", "id=1e400", "id=-1", "id=nan"):
        body = get(f"{server}/compare?{query}")[2].decode()
        assert 'id="empty"' in body, query


def test_a_port_in_use_is_one_line_and_ctrl_c_stops_the_server(archive, server, capsys):
    port = server.rsplit(":", 1)[1]
    assert main(["serve", "--archive", str(archive), "--port", port]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--port: 127.0.0.1:{port} cannot be listened on" in err
    process, url = start(archive)
    assert get(f"{url}/shots")[0] == 200
    process.send_signal(signal.SIGINT)
    process.wait(timeout=20)
    assert "Traceback" not in process.stderr.read()


def _rows(page):
    page.wait_for_selector("#scatter[data-drawn]")  # the page loaded and its chart drawn
    return [[c.strip() for c in row] for row in page.eval_on_selector_all(
        "#shots tbody tr", "rows => rows.map(r => [...r.cells].map(c => c.textContent))")]


def test_the_shots_page_filters_sorts_and_exports_what_it_shows(page, server):
    page.goto(f"{server}/shots")
    rows = _rows(page)
    screenshot(page, "serve-shots")
    assert len(rows) == 3 and page.text_content("#count").startswith("3 of 3 runs")
    assert page.get_attribute("#scatter", "data-drawn") == "3"
    assert page.locator("#scatter canvas").count() == 1
    assert HOSTILE in [r[2] for r in rows]  # the name is text on the page
    assert page.evaluate("window.pwned") is None
    # sorted by v0, descending: a click on its heading twice
    page.click("#shots th:nth-child(6) a")
    page.click("#shots th:nth-child(6) a")
    assert [r[5] for r in _rows(page)] == ["250.00", "243.50", "230.00"]
    assert "sort=v0" in page.url and "desc=1" in page.url
    # filtered in place, and the view survives a reload by its URL
    page.fill("input[name=v0_min]", "240")
    page.click("#filters button")
    assert [r[5] for r in _rows(page)] == ["250.00", "243.50"]
    kept = page.url
    page.goto(kept)
    assert [r[5] for r in _rows(page)] == ["250.00", "243.50"]
    assert page.get_attribute("#scatter", "data-drawn") == "2"
    # the CSV holds the rows shown, in their order and units
    response = page.request.get(server + page.get_attribute("#csv", "href"))
    table = list(csv.reader(io.StringIO(response.text())))
    assert table[0][:5] == ["#", "shot", "version", "created", "v0 [m/s]"]
    assert [float(r[4]) for r in table[1:]] == [250.0, 243.5]
    assert [r[0] for r in table[1:]] == [r[1] for r in _rows(page)]
    # a text a spreadsheet would run (the hostile name starts with =) is written as text
    assert [r[1] for r in table[1:]] == ["'" + HOSTILE, "shot_243.5"]


def test_a_shots_page_draws_its_pulse_and_lists_its_figures_and_warnings(page, server,
                                                                         archive):
    page.goto(f"{server}/shots?sort=v0")
    page.click("#shots tbody tr:first-child td.shot a")
    page.wait_for_selector("#pulse[data-drawn]")
    screenshot(page, "serve-shot")
    assert page.url == f"{server}/shot/1"
    assert page.text_content("#entry").startswith("shot_230@1")
    assert int(page.get_attribute("#pulse", "data-drawn")) > 1000
    assert page.locator("#pulse canvas").count() == 1
    figures = dict(page.eval_on_selector_all(
        "#figures tr", "rows => rows.map(r => [r.cells[0].textContent, r.cells[1].textContent])"))
    summary = json.loads((archive / "shot_230" / "v0001" / "summary.json").read_text())
    assert figures["Peak acceleration (raw)"] == f"{summary['peak_kg']:,.5f} kG"
    assert figures["Pulse duration"] == f"{summary['pulse_duration'] * 1e3:,.4f} ms"
    warnings = summary["warnings"]
    shown = page.eval_on_selector_all("#warnings li", "items => items.map(i => i.textContent)")
    assert shown == warnings
    assert page.locator("#inputs tr").count() > 20
    assert page.text_content("#provenance").count("integrator") >= 1
    # the hostile row's entry (its files are shot_250's) is refused as show refuses it, in
    # words on the page, its script text
    response = page.goto(f"{server}/shot/3")
    assert response.status == 404 and page.evaluate("window.pwned") is None
    said = page.text_content("#message")
    assert said.startswith(f"row #3: it says {HOSTILE}@1, but its folder shot_250/v0001 holds "
                           "shot_250@1"), said
    page.errors.remove("Failed to load resource: the server responded with a status of 404 "
                       "(Not Found)")


def test_the_view_opens_the_sqlite_index_read_only(archive, server):
    """The server never writes the index: its bytes and its write-ahead log are as they were
    after the pages were read."""
    before = (archive / "index.sqlite").read_bytes()
    for path in ("/shots", "/shot/1", "/shots.csv"):
        assert get(server + path)[0] == 200
    assert (archive / "index.sqlite").read_bytes() == before
    assert os.path.getsize(archive / "index.sqlite") == len(before)


def test_the_web_extra_missing_is_one_line_from_the_cli_and_the_api(tmp_path, capsys,
                                                                    monkeypatch):
    """Without Starlette (its import fails), serve is one line naming the extra, exit 2, from
    the CLI; the API raises the same OptionError (it escaped as a traceback from the
    application's build)."""
    import airgun_xl

    monkeypatch.setitem(sys.modules, "starlette", None)
    assert main(["serve", "--archive", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "needs the web extra" in err and "Traceback" not in err
    with pytest.raises(airgun_xl.OptionError, match="pip install 'airgun-xl\\[web\\]'"):
        airgun_xl.serve(tmp_path)


def test_no_archive_or_a_bad_port_is_one_line(tmp_path, capsys):
    for args, said in ((["--archive", str(tmp_path / "none")], "no such archive"),
                       (["--archive", str(tmp_path), "--port", "70000"],
                        "--port: found '70000', expected a port from 0 to 65535")):
        assert main(["serve", *args]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err, err


def test_a_server_archive_is_browsed_as_an_sqlite_one(tmp_path, server_env, browser, capsys):
    """An archive whose index is on a PostgreSQL server (README's administrator makes it, an
    engineer fills into it with $AIRGUN_XL_INDEX): its shots page lists the fills, and a
    shot's page draws its pulse, in Chromium, with no page error and no request elsewhere."""
    root = tmp_path / "shared"
    address = os.environ["AIRGUN_XL_INDEX"].replace("//lab@", "//lab_admin@")
    assert main(["archive", "init", str(root), "--index", address, "--writers", "lab"]) == 0
    _fill(tmp_path, root, SPEEDS[:2], "shared")
    capsys.readouterr()
    process, url = start(root)
    try:
        with watched(browser, url) as page:
            page.goto(f"{url}/shots?sort=v0")
            assert [r[2] for r in _rows(page)] == ["shared_230", "shared_243.5"]
            page.fill("input[name=v0_min]", "240")  # filtered, and kept by the URL
            page.click("#filters button")
            page.goto(page.url)
            assert [r[2] for r in _rows(page)] == ["shared_243.5"]
            table = list(csv.reader(io.StringIO(page.request.get(
                url + page.get_attribute("#csv", "href")).text())))
            assert [r[1] for r in table[1:]] == ["shared_243.5"]
            page.goto(f"{url}/shots?sort=v0")
            page.click("#shots tbody tr:first-child td.shot a")
            page.wait_for_selector("#pulse[data-drawn]")
            assert page.text_content("#entry").startswith("shared_230@1")
            # the laws page, the compare page: drawn from the server's archive as well
            page.goto(f"{url}/compare?id=1&id=2")
            page.wait_for_selector("#overlay[data-drawn]")
            assert page.get_attribute("#overlay", "data-series") == "2"
            page.goto(f"{url}/laws")
            assert page.text_content("#no-laws").startswith("No crush law")
            store_law(root, "LOT-S", LEGACY_LAW.scaled(1.1), [], [])  # listed at once
            page.goto(f"{url}/laws")
            page.wait_for_selector(".law-chart[data-drawn]")
            assert page.text_content("section.lot h2") == "LOT-S"
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=20)
    # the view's sessions are read-only: the server itself refuses a write in them (the same
    # INSERT in an ordinary session reaches the table, and its foreign key refuses it)
    from airgun_xl.archive import Archive
    from airgun_xl.archive.agent import LinkError

    insert = ("INSERT INTO airgun_xl.entries (archive, id, shot, version, path, created) "
              "VALUES ('none', 0, 'x', 1, 'x/v0001', '2026-01-01')")
    for read_only, said in ((True, "read-only transaction"), (False, "foreign key")):
        found = Archive(root)
        found.index.read_only = read_only
        with pytest.raises(LinkError, match=said):
            found.index._connection().execute(insert)
        found.index.close()
