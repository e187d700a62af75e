"""Shared helpers: the legacy cases and reading result columns back from a workbook."""
import airgun_xl  # noqa: F401 - first: it pins OpenBLAS's kernel before numpy loads (blas.py)

# isort: split
import json
from pathlib import Path

import numpy as np
import openpyxl
import pytest

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "legacy_reference"
TEMPLATE = ROOT / "templates" / "shot_a.xlsx"
CASES = json.loads((REFERENCE / "cases.json").read_text())

#: Calc and Excel store 15 significant digits: a faithful port agrees to 1e-12 of the column's
#: largest magnitude (the rule of legacy_reference/README.md).
LEGACY_RTOL = 1e-12

#: Result columns the macro writes values into, by letter.
MACRO_COLUMNS = ("H", "I", "J", "K", "L", "M", "N", "S", "T", "U", "AB")


def sheet_values(path):
    """{(row, col_letter): value} of the first sheet, read with openpyxl (values only)."""
    wb = openpyxl.load_workbook(path, read_only=True, data_only=True)
    ws = wb.worksheets[0]
    cells = {}
    for row in ws.iter_rows():
        for cell in row:
            if cell.value is not None and hasattr(cell, "column_letter"):
                cells[(cell.row, cell.column_letter)] = cell.value
    wb.close()
    return cells


def column(cells, letter, rows):
    """Rows 2..rows+1 of a column as floats, NaN where empty."""
    return np.array([cells.get((r, letter), np.nan) for r in range(2, rows + 2)], dtype=float)


def relative_error(a, b):
    """Largest |a - b| over the largest |b|, NaN positions required to agree."""
    assert np.array_equal(np.isnan(a), np.isnan(b)), "empty cells differ"
    scale = np.nanmax(np.abs(b)) if np.isfinite(b).any() else 0.0
    diff = np.nanmax(np.abs(a - b)) if np.isfinite(b).any() else 0.0
    return diff / scale if scale else diff


def macro_rows(cells):
    """Time rows of a filled sheet: the last row of column H, less the header."""
    return max(r for (r, c) in cells if c == "H") - 1


def columns_off_the_macro(legacy, new):
    """The macro's columns (MACRO_COLUMNS) where ``new`` is further than LEGACY_RTOL from
    ``legacy`` (both from :func:`sheet_values`); [] when the port agrees everywhere."""
    rows = macro_rows(legacy)
    off = []
    for letter in MACRO_COLUMNS:
        expected, got = column(legacy, letter, rows + 3), column(new, letter, rows + 3)
        if letter == "I":  # the final masses below I are compared on their own
            expected, got = expected[:rows], got[:rows]
        if not relative_error(got, expected) <= LEGACY_RTOL:
            off.append(letter)
    return off


def write_trace_csv(path, trace):
    """``trace`` (time [s], accel_kg [kG]) as a measured-pulse CSV, every float exact."""
    path.write_text("time [s],acceleration [kG]\n" + "".join(
        f"{t!r},{a!r}\n" for t, a in zip(trace.time.tolist(), trace.accel_kg.tolist(),
                                           strict=True)))
    return path


def command_options(command="fill", **given):
    """The namespace ``command``'s real parser makes of option texts given by their dests
    (``time_slack="10%"``), after stand-in positionals; ``record`` is the specification's
    field as a sheet writes it (``cfc600``, ``unfiltered``), given as ``--cfc``."""
    from airgun_xl.cli.commands import build_parser

    if given.get("record") is not None:
        record = given.pop("record").strip().lower()
        given["cfc"] = "none" if record == "unfiltered" else record.removeprefix("cfc").strip()
    argv = [f"--{dest.replace('_', '-')}={text}" for dest, text in given.items()
            if text is not None]
    positionals = ["s.xlsx", "r.csv"] if command in ("accept", "compare-measured",
                                                      "calibrate") else ["s.xlsx"]
    return build_parser().parse_args([command, *positionals, *argv])


def template_with(tmp_path, **cells):
    """A copy of the template in ``tmp_path`` with some parameter cells changed (openpyxl)."""
    shot = tmp_path / "shot.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    for address, value in cells.items():
        wb["Sheet1"][address] = value
    wb.save(shot)
    return shot


@pytest.fixture
def shot_copy(tmp_path):
    """A copy of the template in tmp_path, so tests can fill it beside itself."""
    path = tmp_path / "shot.xlsx"
    path.write_bytes(TEMPLATE.read_bytes())
    return path


#: Modules whose tests take a second or more each (child processes, LibreOffice, fills of
#: long runs, Monte Carlo and calibration): marked slow, so that pytest -m "not slow" runs the
#: rest in about a minute (issue 24.8). Measured with --durations on the CI's 2-core VM.
SLOW_MODULES = {
    "test_readme_workflow", "test_report_workbooks", "test_printing", "test_campaign",
    "test_recorder", "test_design", "test_design_srs", "test_calibrate", "test_cluster",
    "test_writer_fallback", "test_hostile_faults", "test_hostile_inputs",
    "test_hostile_outputs", "test_hostile_properties", "test_hostile_measured_properties",
    "test_hostile_spec_properties",
    "test_hostile_archive", "test_pure_python", "test_typing", "test_sensitivity",
    "test_calibration_intervals", "test_benchmarks", "test_golden_commands",
    "test_api_properties", "test_closed_loop", "test_pdf_report",
}


#: Single tests of a second or more in the other modules (their names, parameters aside).
SLOW_TESTS = {
    "test_output_is_deterministic", "test_a_fill_killed_at_random_moments_leaves_the_archive_whole",
    "test_parameter_block_is_copied_with_formulas",
    "test_a_long_run_fits_the_sheet_and_keeps_everything_in_the_sidecar",
    "test_parameters_round_trip_exactly", "test_reduced_models_run",
    "test_libreoffice_reads_the_output", "test_summary_matches_the_report_figures",
    "test_two_processes_filling_at_once_lose_nothing", "test_libreoffice_renders_every_chart",
    "test_two_fills_making_one_archive_at_once_both_find_it_whole",
    "test_the_estimate_is_above_the_measured_peak",
    "test_23_11_durations_with_an_exponent_and_a_unit_run",
    "test_23_16_a_file_size_limit_is_one_line_with_no_zipfile_traceback",
    "test_an_error_cell_in_the_parameters_is_read",
    "test_template_at_half_a_microsecond_has_12002_rows", "test_libreoffice_reads_the_template",
    "test_the_reported_probability_agrees_with_an_independent_monte_carlo_of_2000_fills",
    "test_design_confidence_says_when_no_setting_reaches_it", "test_design_confidence_met_exits_0",
    "test_the_closed_form_critical_step_agrees_with_the_bisection",
    "test_32_12_accept_judges_a_recording_of_1_2_million_samples",
    "test_the_short_version_agrees_with_formulas",
    # over half a second each, so that the rest stays under a minute on a busy VM
    "test_every_tenth_row_and_its_sidecar",
    "test_23_15_a_full_disk_while_the_journal_is_written_is_one_line",
    "test_fill_says_the_notice_before_it_starts",
    "test_fill_judges_the_prediction_by_the_sheet_and_options_override_it",
    "test_design_by_the_specification_writes_the_middle", "test_only_accel_and_filtered",
    "test_a_final_mass_outside_has_no_time_not_an_error_cell",
    "test_outputs_block_in_the_workbook", "test_tracked_sheet_holds_the_kernel_values",
    # issue 60's Monte Carlo and design runs (10-20 s each)
    "test_fill_and_design_confidence_agree_on_the_proposal",
    "test_design_and_next_given_the_same_law_gun_and_specification_propose_the_same_setting",
    "test_the_model_error_widens_p_pass_as_its_spread_says",
    "test_the_interval_takes_in_the_model_errors_own_uncertainty",
    "test_fill_says_pass_exactly_when_the_monte_carlo_says_at_least_half",
}


@pytest.fixture(scope="session")
def pg_server():
    """A real PostgreSQL server for the session (tests/pg_server.py); skipped, with what to
    install, without the server's binaries or psycopg."""
    import pg_server as pg

    if not pg.available():
        pytest.skip(pg.WHY_SKIPPED)
    server = pg.start_server()
    yield server
    pg.remove_server(server)


@pytest.fixture
def server_env(pg_server, monkeypatch):
    """The archive role's address in $AIRGUN_XL_INDEX and its password in $PGPASSWORD, as a
    lab engineer's shell would have them; returns the server."""
    import pg_server as pg

    monkeypatch.setenv("AIRGUN_XL_INDEX", pg_server.address)
    monkeypatch.setenv("PGPASSWORD", pg.PASSWORD)
    for name in ("PGHOST", "PGPORT", "PGUSER", "PGDATABASE", "PGSERVICE", "PGPASSFILE"):
        monkeypatch.delenv(name, raising=False)
    return pg_server


@pytest.fixture(scope="module")
def browser():
    """Debian's Chromium under Playwright, for a module's browser tests (tests/serve_helpers.py);
    skipped without it."""
    from serve_helpers import chromium

    with chromium() as launched:
        yield launched


@pytest.fixture
def page(browser, server):
    """A fresh page on the module's ``server`` fixture that fails the test on any page error
    or any request to another address."""
    from serve_helpers import watched

    with watched(browser, server) as page:
        yield page


#: The longest test files, longest first (seconds a file on 2 cores, measured in a whole run):
#: README's test command runs them on every core with one file a worker's unit
#: (``-n auto --dist loadfile``), which hands the files out in the order collected, so these
#: go first; a long file handed out last would leave the other cores idle at the end.
LONGEST_FIRST = ("test_calibration_intervals", "test_golden_commands", "test_readme_workflow",
                 "test_report_workbooks", "test_benchmarks", "test_closed_loop",
                 "test_hostile_fifth_pass", "test_first_shot", "test_outputs", "test_fill",
                 "test_closed_loop_whole", "test_pdf_report")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if (item.module.__name__.rsplit(".", 1)[-1] in SLOW_MODULES
                or item.originalname in SLOW_TESTS):
            item.add_marker(pytest.mark.slow)
    if hasattr(config, "workerinput"):  # a pytest-xdist worker: the longest files first
        rank = {name: k for k, name in enumerate(LONGEST_FIRST)}
        items.sort(key=lambda item: rank.get(item.module.__name__.rsplit(".", 1)[-1],
                                             len(rank)))
