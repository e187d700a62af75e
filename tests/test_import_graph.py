"""Issue 34: one way through the house. The package's import graph, built by import-linter's
graph library (grimp), has no cycle among the package's modules, counting imports made inside
functions and leaving out only those under ``if TYPE_CHECKING:``; and every ``.py`` file of
the package is a node of it (a folder without ``__init__.py`` would be left out).

The layers contract in ``pyproject.toml`` holds (``lint-imports``), covers every package and
top-level module, is the picture ``docs/layout.md`` draws, and fails when a layer imports up.
"""
import re
import shutil
import subprocess
import sys
import tomllib
import warnings
from pathlib import Path

import pytest

grimp = pytest.importorskip("grimp")

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "airgun_xl"
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
LAYERS = next(c for c in CONFIG["contracts"] if c["type"] == "layers")["layers"]


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph("airgun_xl", exclude_type_checking_imports=True)


def _module(path):
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_every_python_file_of_the_package_is_in_the_graph(graph):
    files = {_module(p) for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts}
    assert len(files) > 100
    assert files - set(graph.modules) == set()


def test_no_import_cycle_among_the_packages_modules(graph):
    """Strongly connected components over the direct imports (scipy's csgraph): the graph
    has no cycle when each component is one module (and no module imports itself)."""
    import numpy as np
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    modules = sorted(graph.modules)
    index = {m: k for k, m in enumerate(modules)}
    pairs = [(index[m], index[i]) for m in modules
             for i in graph.find_modules_directly_imported_by(m)]
    assert all(a != b for a, b in pairs)
    rows, cols = zip(*pairs, strict=True)
    matrix = csr_matrix((np.ones(len(pairs)), (rows, cols)), shape=(len(modules),) * 2)
    _, labels = connected_components(matrix, directed=True, connection="strong")
    cycles = [sorted(m for m, label in zip(modules, labels, strict=True) if label == c)
              for c in set(labels.tolist()) if np.sum(labels == c) > 1]
    assert cycles == [], cycles


def test_function_level_imports_are_counted(graph):
    """The graph sees an import made inside a function: shot.py reads a workbook through
    readers.shot_workbook only inside Shot.from_workbook."""
    details = graph.get_import_details(importer="airgun_xl.shot",
                                       imported="airgun_xl.readers.shot_workbook")
    assert details and all(d["line_contents"].startswith("from .readers.shot_workbook")
                           for d in details)


def _lint_imports(cwd):
    """``lint-imports`` (the console script beside this interpreter) run in ``cwd``."""
    script = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    assert script is not None, "import-linter is in the test extra"
    return subprocess.run([script, "--no-cache"], cwd=cwd, capture_output=True, text=True,
                          timeout=300)


def test_lint_imports_keeps_every_contract():
    done = _lint_imports(ROOT)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 broken" in done.stdout and "5 kept" in done.stdout, done.stdout


def test_the_layers_contract_covers_every_package_and_top_level_module():
    """Each child of ``airgun_xl`` (a package, or a module other than ``__init__``) is named
    in exactly one layer."""
    children = {p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    children |= {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    named = [n.strip() for layer in LAYERS for n in layer.split("|")]
    assert sorted(named) == sorted(children)


def test_docs_layout_draws_the_layers_the_contract_declares():
    """docs/layout.md's layer table lists the contract's layers, top to bottom, with the
    same siblings (and nothing the contract does not check)."""
    text = (ROOT / "docs" / "layout.md").read_text()
    rows = re.findall(r"^\| (\d+) \| ([^|]+) \|", text, flags=re.M)
    drawn = [[n.strip(" `") for n in names.split(",")] for _, names in rows]
    declared = [[n.strip() for n in layer.split("|")] for layer in LAYERS]
    assert [sorted(d) for d in drawn] == [sorted(d) for d in declared]
    assert [int(k) for k, _ in rows] == list(range(len(LAYERS), 0, -1))


def _copy_package(folder):
    """The package's sources and the contracts, copied to ``folder`` to be broken there."""
    shutil.copytree(PACKAGE, folder / "airgun_xl",
                    ignore=shutil.ignore_patterns("__pycache__", "*.so", "*.pyd"))
    shutil.copy(ROOT / "pyproject.toml", folder / "pyproject.toml")


def test_the_contract_fails_when_a_reader_imports_up(tmp_path):
    """The same contract on a copy of the package where the recording reader imports the
    CLI: lint-imports names that import and exits 1 (the check can fail)."""
    _copy_package(tmp_path)
    reader = tmp_path / "airgun_xl" / "readers" / "recording.py"
    reader.write_text(reader.read_text() + "\n\ndef _up():\n    from ..cli import main\n"
                      "    return main\n")
    done = _lint_imports(tmp_path)
    assert done.returncode == 1, done.stdout
    assert "airgun_xl.readers.recording -> airgun_xl.cli" in done.stdout
    assert "the errors at the ground BROKEN" in done.stdout, done.stdout


def test_the_thin_cli_contract_fails_when_a_moved_command_reaches_below_app(tmp_path):
    """Issue 44: on a copy of the package where cli/srs.py imports a study itself,
    lint-imports names that import under the forbidden contract; and the contract ignores no
    import (every command has moved under app/)."""
    _copy_package(tmp_path)
    command = tmp_path / "airgun_xl" / "cli" / "srs.py"
    command.write_text(command.read_text() + "\n\ndef _down():\n"
                       "    from ..studies.shock import srs\n    return srs\n")
    done = _lint_imports(tmp_path)
    assert done.returncode == 1, done.stdout
    assert "airgun_xl.cli.srs -> airgun_xl.studies.shock" in done.stdout
    assert "only through app BROKEN" in done.stdout, done.stdout
    thin = next(c for c in CONFIG["contracts"] if c["id"] == "thin-cli")
    assert thin.get("ignore_imports", []) == []


@pytest.mark.parametrize("old, new, name", [
    ("trace", "airgun_xl.readers.recording", "read_trace"),
    ("reader", "airgun_xl.readers.shot_workbook", "read_params"),
    ("writer", "airgun_xl.reports.fill", "write_workbook"),
])
def test_the_old_paths_still_import_with_a_deprecation_warning(old, new, name):
    """The three old paths a user may hold give the same objects as their new homes, and
    warn (in a fresh interpreter: this one may have imported them already)."""
    code = (f"import warnings; warnings.simplefilter('error', DeprecationWarning)\n"
            f"try:\n    import airgun_xl.workbook.{old}\nexcept DeprecationWarning as w:\n"
            f"    print(w)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.stdout.strip() == (f"airgun_xl.workbook.{old} is deprecated and goes in the "
                                   f"next release: import {new}"), done.stdout + done.stderr
    import importlib

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        shim = importlib.import_module(f"airgun_xl.workbook.{old}")
    assert getattr(shim, name) is getattr(importlib.import_module(new), name)


def test_no_function_of_the_cli_is_over_40_lines():
    """Issue 44: the CLI parses into a request and prints the outcome; a function that grows
    past 40 lines is composing work that belongs under app/."""
    import ast

    long = []
    for path in sorted((PACKAGE / "cli").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                size = node.end_lineno - node.lineno + 1
                if size > 40:
                    long.append(f"{path.name}:{node.name} ({size} lines)")
    assert long == []
