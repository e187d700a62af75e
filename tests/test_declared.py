"""Issue 61: a command declared once, as its request's fields (airgun_xl/app/declared.py).

For each command converted so far (``srs`` first, as the issue asks): the Python API
function's keywords are its request's fields with their defaults, its body is the request
made and run, the command's options are built from the same fields (their dests the fields'
names), and every field checks itself, a refusal naming the keyword (the command line's the
flag)."""
import ast
import dataclasses
import inspect
import textwrap

import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.app.archive import CompareRequest, HistoryRequest, ShowRequest
from airgun_xl.app.check import CheckRequest
from airgun_xl.app.compare_measured import CompareMeasuredRequest
from airgun_xl.app.convergence import ConvergenceRequest
from airgun_xl.app.declared import option_of
from airgun_xl.app.diff import DiffRequest
from airgun_xl.app.recording import RecordingRequest
from airgun_xl.app.srs import SrsRequest
from airgun_xl.app.sweep import SweepRequest
from airgun_xl.app.template import TemplateRequest
from airgun_xl.cli.commands import build_parser
from airgun_xl.errors import OptionError
from airgun_xl.web.command import ServeRequest

#: The commands declared once so far: (command, API function, request).
DECLARED = [("srs", airgun_xl.srs, SrsRequest), ("check", airgun_xl.check, CheckRequest),
            ("diff", airgun_xl.diff, DiffRequest),
            ("recording", airgun_xl.recording, RecordingRequest),
            ("template", airgun_xl.template, TemplateRequest),
            ("convergence", airgun_xl.convergence, ConvergenceRequest),
            ("compare-measured", airgun_xl.compare_measured, CompareMeasuredRequest),
            ("show", airgun_xl.show, ShowRequest), ("compare", airgun_xl.compare, CompareRequest),
            ("sweep", airgun_xl.sweep, SweepRequest), ("serve", airgun_xl.serve, ServeRequest),
            ("history", airgun_xl.history, HistoryRequest)]

#: A keyword a function has always taken by position too (documented so): (function, name).
POSITIONAL = {("convergence", "levels"), ("show", "archive"), ("compare", "archive"),
              ("sweep", "vary"), ("serve", "archive"), ("history", "archive")}


def _subparser(command):
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return sub.choices[command]


@pytest.mark.parametrize("command,function,request_type", DECLARED,
                         ids=[c for c, _, _ in DECLARED])
def test_the_functions_keywords_are_its_requests_fields(command, function, request_type):
    fields = {f.name: f for f in dataclasses.fields(request_type)}
    parameters = inspect.signature(function).parameters
    assert set(parameters) == set(fields)
    for name, parameter in parameters.items():
        field = fields[name]
        if field.default is dataclasses.MISSING:
            assert parameter.default is inspect.Parameter.empty, name
        else:
            assert parameter.default == field.default, name
            assert parameter.kind is inspect.Parameter.KEYWORD_ONLY or \
                (command, name) in POSITIONAL, name


@pytest.mark.parametrize("command,function,request_type", DECLARED,
                         ids=[c for c, _, _ in DECLARED])
def test_the_functions_body_makes_the_request_and_runs_it(command, function, request_type):
    """Its docstring, the import, ``return run(Request.given(every keyword))``."""
    source = textwrap.dedent(inspect.getsource(inspect.unwrap(function)))
    body = ast.parse(source).body[0].body
    docstring, *rest = body
    assert isinstance(docstring, ast.Expr) and isinstance(docstring.value, ast.Constant)
    assert [type(s) for s in rest] == [ast.ImportFrom, ast.Return]
    call = rest[1].value
    assert isinstance(call, ast.Call) and call.func.id == "run"
    (made,) = call.args
    assert made.func.attr == "given" and made.func.value.id == request_type.__name__
    assert {k.arg: k.value.id for k in made.keywords} == {
        f.name: f.name for f in dataclasses.fields(request_type)}


@pytest.mark.parametrize("command,function,request_type", DECLARED,
                         ids=[c for c, _, _ in DECLARED])
def test_the_commands_options_are_the_requests_fields(command, function, request_type):
    """Each field is an argument stored at the field's name, spelt as declared."""
    parser = _subparser(command)
    by_dest = {}
    for action in parser._actions:
        by_dest.setdefault(action.dest, []).extend(action.option_strings or [action.dest])
    for field in dataclasses.fields(request_type):
        spelt = option_of(field)
        assert set(spelt.flags) | {a for a, _ in spelt.aliases} <= set(by_dest[field.name]), \
            field.name


@pytest.mark.parametrize("keyword,value,said", [
    ("q", 0, "q: found '0'"), ("q", True, "q: found True"),
    ("cfc", 601, "cfc: "), ("cfc", float("nan"), "cfc: found nan"),
    ("lo", "low", "lo: found 'low', expected a number"),
    ("hi", None, "hi: found None, expected a number"),
    ("integrator", "rk4", "integrator: found 'rk4', expected one of legacy, newmark"),
    ("model", "5-mass", "model: found '5-mass', expected one of 4-mass, rigid"),
    ("force", "yes", "force: found 'yes', expected True or False"),
    ("crush_law", "", "crush_law: found ''"),
    ("shot", 12, "shot: found 12, expected a path"),
])
def test_a_request_checks_itself_naming_the_keyword(keyword, value, said):
    """``check(integrator="rk4")`` answered about an integrator that does not exist (only
    argparse refused it), and ``srs(q=0)`` said "--srs-q": the request refuses, naming the
    keyword, before any work."""
    given = {"shot": TEMPLATE, keyword: value}
    with pytest.raises(OptionError) as caught:
        SrsRequest.given(**given)
    assert str(caught.value).startswith(said), caught.value


def test_check_refuses_an_integrator_that_does_not_exist():
    """The issue's case: ``check(integrator="rk4")`` answered about a scheme that does not
    exist; it is refused naming the keyword, the command naming its option (argparse's)."""
    with pytest.raises(OptionError, match=r"^integrator: found 'rk4', expected one of "
                                          r"legacy, newmark$"):
        airgun_xl.check(TEMPLATE, integrator="rk4")


def test_a_request_is_keyword_only_and_frozen():
    with pytest.raises(TypeError):
        SrsRequest(TEMPLATE)  # type: ignore[misc]
    request = SrsRequest.given(shot=str(TEMPLATE), q="20", cfc="none", lo="200")
    assert (request.shot, request.q, request.cfc, request.lo) == (TEMPLATE, 20.0, None, 200.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        request.q = 5.0  # type: ignore[misc]


@pytest.mark.parametrize("keyword,value,said", [
    ("rtol", -1e-3, "rtol: found -0.001, expected a number >= 0"),
    ("atol", "nan", "atol: found 'nan', expected a number >= 0"),
    ("rtol", "tight", "rtol: found 'tight', expected a number >= 0"),
    ("report", 3, "report: found 3, expected a path"),
])
def test_diffs_request_refuses_naming_the_keyword(keyword, value, said):
    """``diff(rtol=-1e-3)`` compared with a negative tolerance (every column then differs,
    and the report said so without a word on why); the API said "--rtol" of a keyword."""
    with pytest.raises(OptionError) as caught:
        DiffRequest.given(legacy=TEMPLATE, new=TEMPLATE, **{keyword: value})
    assert str(caught.value) == said


def test_diffs_command_line_names_the_flag(capsys):
    from airgun_xl.cli import main

    assert main(["diff", str(TEMPLATE), str(TEMPLATE), "--atol", "-2"]) == 2
    assert capsys.readouterr().err.strip().endswith("--atol: found '-2', expected a number >= 0")


def test_a_recording_is_kept_as_the_text_given():
    """A workbook's columns are text with colons (``trace.xlsx:Sheet1!A:B``): kept as given,
    not made a path (Windows reads a colon as a drive's); a path given as one is its text;
    anything else refused naming the keyword."""
    from pathlib import Path

    assert RecordingRequest.given(path="t.xlsx:Sheet1!A:B").path == "t.xlsx:Sheet1!A:B"
    assert RecordingRequest.given(path=Path("r.csv")).path == "r.csv"
    with pytest.raises(OptionError, match=r"^path: found b'r.csv', expected a recording's"):
        RecordingRequest.given(path=b"r.csv")


def test_serve_refuses_naming_the_keyword_and_the_command_its_flag(tmp_path, capsys,
                                                                   monkeypatch):
    """``serve(port=70000)`` and no archive at all: one line naming the keyword from the
    API, the flag from the command line, before anything listens."""
    from airgun_xl.cli import main

    monkeypatch.delenv("AIRGUN_XL_ARCHIVE", raising=False)
    with pytest.raises(OptionError, match=r"^port: found 70000, expected a port from 0 to "
                                          r"65535$"):
        airgun_xl.serve(tmp_path, port=70000)
    with pytest.raises(OptionError, match=r"^archive: found no archive, expected archive DIR"):
        airgun_xl.serve()
    assert main(["serve"]) == 2
    assert capsys.readouterr().err == ("airgun-xl: error: --archive: found no archive, "
                                       "expected --archive DIR (or $AIRGUN_XL_ARCHIVE)\n")
