"""Issue 34: one way through the house. The package's import graph, built by import-linter's
graph library (grimp), has no cycle among the package's modules, counting imports made inside
functions and leaving out only those under ``if TYPE_CHECKING:``; and every ``.py`` file of
the package is a node of it (a folder without ``__init__.py`` would be left out)."""
from pathlib import Path

import pytest

grimp = pytest.importorskip("grimp")

PACKAGE = Path(__file__).resolve().parents[1] / "airgun_xl"


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
    workbook.reader only inside Shot.from_workbook."""
    details = graph.get_import_details(importer="airgun_xl.shot",
                                       imported="airgun_xl.workbook.reader")
    assert details and all(d["line_contents"].startswith("from .workbook.reader")
                           for d in details)
