"""Issue 48: the view's URL is untrusted input. Whatever a URL holds, the shots page reads its
choices without an error (a value it does not know is the default), its own links give back
exactly the choices they were made from (a view survives a reload and a link), a compare URL
names at most eight entries, each once, and the rows sort whatever their values' types
(property tests, hypothesis, fixed seed)."""
from urllib.parse import urlencode

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("starlette")
from starlette.datastructures import QueryParams  # noqa: E402

from airgun_xl.web import pages  # noqa: E402
from airgun_xl.web.listing import Snapshot  # noqa: E402

PROPERTY = settings(max_examples=300, deadline=None, derandomize=True)

#: Values a hostile or mistyped URL gives: numbers in every spelling, texts, the choices'
#: own words, scripts.
VALUES = st.one_of(st.text(max_size=30), st.sampled_from(
    ["", "1", "0", "-0", "nan", "inf", "-inf", "1e999", "1e-320", "240", "243.53532",
     "228.94303800817744", "peak_kg", "pulse_duration", "A28", "E43", "lot", "verdict",
     "PASS", "FAIL", "none", "(none)", "2026-11-01", "<script>", "=1+1"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr))
KEYS = st.sampled_from([*pages.FILTER_KEYS, "page", "id", "other"])


@PROPERTY
@given(st.lists(st.tuples(KEYS, VALUES), max_size=25))
def test_any_url_is_read_and_the_pages_links_give_its_choices_back(pairs):
    f = pages.filters(QueryParams(urlencode(pairs)))
    for key in ("v0_min", "v0_max", "peak_min", "peak_max", "input_min", "input_max"):
        assert f[key] is None or (isinstance(f[key], float) and abs(f[key]) < float("inf"))
    assert f["sort"] in pages.SORTS and f["colour"] in pages.COLOURS
    assert f["verdict"] in ("", "PASS", "FAIL", "none")
    assert f["input"] in ("", *pages.cells()) and f["x"] in pages.cells()
    link = pages.url("/shots", f)
    assert link.startswith("/shots")
    assert pages.filters(QueryParams(link.partition("?")[2])) == f


@PROPERTY
@given(st.lists(st.tuples(st.just("id"), VALUES), max_size=30))
def test_a_compare_url_names_at_most_eight_entries_each_once(pairs):
    ids = pages.compared_ids(QueryParams(urlencode(pairs)))
    assert len(ids) <= pages.MAX_COMPARED and len(set(ids)) == len(ids)
    assert all(isinstance(i, int) and 0 <= i < 2 ** 63 for i in ids)
    assert pages.compared_ids(QueryParams(pages.compare_url(ids).partition("?")[2])) == ids


ROW_VALUES = st.one_of(st.none(), st.booleans(), st.integers(), st.text(max_size=8),
                       st.floats(allow_nan=False, allow_infinity=False))


@PROPERTY
@given(st.lists(st.fixed_dictionaries({key: ROW_VALUES for key, *_ in pages.COLUMNS}),
                max_size=12), st.sampled_from(pages.SORTS), st.booleans())
def test_rows_of_any_values_sort_and_filter(rows, sort, desc):
    """Rows as a damaged archive could give them (a figure that is text, a None): every
    sort gives every row once, those without the sorted value last."""
    listed = [{**r, "id": k, "inputs": {}, "figures": {}} for k, r in enumerate(rows)]
    snapshot = Snapshot([], {}, listed, [], [], {})
    f = {**pages.filters(QueryParams("")), "sort": sort, "desc": desc}
    out = pages.selected(snapshot, f)
    assert sorted(r["id"] for r in out) == list(range(len(rows)))
    missing = [r["id"] for r in out if r.get(sort) is None]
    assert [r["id"] for r in out[len(out) - len(missing):]] == missing


def test_a_value_exactly_on_a_limit_is_within_it():
    """v0 = 243.53532 kept by v0_min = v0_max = 243.53532; one ulp past either limit, not."""
    import math

    v = 243.53532
    rows = [{"id": 1, "v0": v, "inputs": {"A28": v}, "figures": {}}]
    snapshot = Snapshot([], {}, rows, [], [], {})
    base = pages.filters(QueryParams(""))
    assert pages.selected(snapshot, {**base, "v0_min": v, "v0_max": v}) == rows
    assert pages.selected(snapshot, {**base, "input": "A28", "input_min": v,
                                     "input_max": v}) == rows
    assert pages.selected(snapshot, {**base, "v0_min": math.nextafter(v, 1e9)}) == []
    assert pages.selected(snapshot, {**base, "v0_max": math.nextafter(v, 0)}) == []


def test_a_run_with_warnings_is_drawn_in_a_series_that_says_so():
    """The scatter's runs with warnings, and those whose warnings were not recorded, are
    series of their own, named so (a figure the tool cannot vouch for is flagged where it is
    drawn); each run is drawn once."""
    rows = [{"id": k, "lot": "L", "warning_count": count, "inputs": {"A28": 240.0 + k},
             "figures": {"peak_kg": 9.0 + k}} for k, count in enumerate((0, 2, None, 0))]
    f = {**pages.filters(QueryParams("")), "colour": "lot"}
    drawn = pages.scatter(rows, f)
    assert [(s["name"], s["points"]) for s in drawn["series"]] == [
        ("L", 2), ("L (warnings not recorded)", 1), ("L (with warnings)", 1)]
    assert sorted(drawn["ids"]) == [0, 1, 2, 3]
