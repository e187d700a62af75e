"""Issue 44: the archive's commands as functions (airgun_xl.app.archive) and as the Python
API (airgun_xl.history, show, compare), driven without the CLI: what they return is what the
fill stored, and their lines are what the commands print."""
import json

import pytest
from conftest import template_with

import airgun_xl
from airgun_xl.app import archive
from airgun_xl.cli import main
from airgun_xl.errors import ArchiveError, OptionError


@pytest.fixture
def filled(tmp_path):
    """An archive with two runs of shot A (A28 200 and 250 m/s)."""
    root = tmp_path / "arch"
    runs = []
    for v in (200, 250):
        (tmp_path / f"v{v}").mkdir()
        shot = template_with(tmp_path / f"v{v}", A28=v)
        runs.append(airgun_xl.fill(shot, archive=root, only="summary", name=f"v{v}"))
    return root, runs


def test_history_lists_what_the_fills_stored(filled, capsys):
    root, runs = filled
    outcome = airgun_xl.history(root)
    assert [r["ref"] for r in outcome.rows] == [run.filled.entry.ref for run in runs]
    assert [r["peak_kg"] for r in outcome.rows] == [run.result.peak_kg for run in runs]
    assert [r["v0"] for r in outcome.rows] == [200.0, 250.0] and outcome.total == 2
    only = airgun_xl.history(root, where="A28=240:260")
    assert [r["v0"] for r in only.rows] == [250.0] and only.lines[-1] == "1 entry of 2 (--where)"
    assert main(["history", "--archive", str(root)]) == 0
    assert capsys.readouterr().out.splitlines() == list(outcome.lines)
    # a bad selection: the API names the keyword, the command line its flag (issue 61)
    with pytest.raises(OptionError, match="^where: found 'Z9=1'"):
        airgun_xl.history(root, where="Z9=1")
    with pytest.raises(OptionError, match="^since: found 'yesterday', expected a date such as "
                                          "2026-11-01$"):
        airgun_xl.history(root, since="yesterday")
    for args, said in ((["--where", "Z9=1"], "--where: found 'Z9=1'"),
                       (["--since", "11/01"], "--since: found '11/01', expected a date")):
        assert main(["history", "--archive", str(root), *args]) == 2
        assert capsys.readouterr().err.startswith(f"airgun-xl: error: {said}")


def test_show_gives_the_entrys_records(filled, capsys):
    root, runs = filled
    outcome = airgun_xl.show("v250", root)
    assert outcome.doc["summary"]["peak_kg"] == runs[1].result.peak_kg
    assert {p["cell"]: p["value"] for p in outcome.doc["params"]}["A28"] == 250
    assert f"  {'Peak acceleration (raw)':<37} {runs[1].result.peak_kg:,.5f} kG" \
        in outcome.lines
    assert main(["show", "v250", "--archive", str(root), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == json.loads(json.dumps(outcome.doc))
    with pytest.raises(ArchiveError):
        airgun_xl.show("nothing", root)


def test_compare_names_the_differing_input_and_the_series(filled):
    root, runs = filled
    same = airgun_xl.compare("v200", "v200", root)
    assert same.same and "inputs: the 23 parameter cells agree" in same.lines
    differ = airgun_xl.compare("v200", "v250", root)
    assert not differ.same and [c for c, *_ in differ.report.inputs] == ["A28", "A29", "A30"]


def test_init_and_verify(tmp_path, filled):
    made = archive.init(str(tmp_path / "new"))
    assert made.lines == (f"made the archive {tmp_path / 'new'}, its index in the folder",)
    root, _ = filled
    clean = archive.verify(str(root))
    assert clean.problems == () and clean.lines == (f"2 entries, 0 problems in {root}",)
    summary = next(root.rglob("summary.json"))
    summary.write_text(summary.read_text().replace("peak_kg", "peak_kG"))
    broken = archive.verify(str(root))
    assert len(broken.problems) == 1 and "summary.json" in broken.problems[0]


@pytest.mark.parametrize("args, said", [
    (["init", "{new}", "--writers", "lab;drop"],
     "--writers: found 'lab;drop', expected a role name: letters, digits and _, at most 63"),
    (["init", "{new}", "--writers", "lab"],
     "--writers: found roles for an archive whose index is in its folder, expected --index "
     "or $AIRGUN_XL_INDEX (a server's roles)"),
    (["verify", "{new}", "--writers", "lab"],
     "--writers: found roles with verify, expected them with init or migrate"),
    (["check", "{new}"], "argument action: invalid choice: 'check'"),
])
def test_archive_maintenance_refuses_in_one_line_naming_the_flag(args, said, tmp_path, capsys,
                                                                  monkeypatch):
    """archive's request (issue 61): a role that is no identifier, roles for a folder's own
    index or for verify; one line, exit 2, nothing made; the request names the keyword."""
    from airgun_xl.app.archive import ArchiveRequest, maintain
    from airgun_xl.errors import OptionError

    monkeypatch.delenv("AIRGUN_XL_INDEX", raising=False)
    new = tmp_path / "new"
    assert main(["archive", *(a.format(new=new) for a in args)]) == 2
    err = capsys.readouterr().err
    assert said in err and err.count("\n") == 1 and not new.exists(), err
    with pytest.raises(OptionError, match="^writers: found roles for an archive whose index"):
        maintain(ArchiveRequest(action="init", folder=str(new), writers=("lab",)))
    assert not new.exists()


def test_archive_verify_json_lists_the_problems(filled, capsys):
    root, _ = filled
    assert main(["archive", "verify", str(root), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["entries"] == 2 and doc["problems"] == [] and doc["archive"] == str(root)
