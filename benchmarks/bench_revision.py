"""Speed against an earlier revision: `airgun-xl fill` of shot A (the full default output, as
bench_fill.py times it) and a campaign of 20 copies with `--jobs 2` (as bench_campaign.py
times it), this tree against ``--base REV``, in the same run on the same machine.

    python benchmarks/bench_revision.py --base REV [--repeat N] [--quick]

The base is checked out with ``git worktree`` into a temp folder and given this tree's
compiled extensions (their C sources must be the same in both: the script refuses
otherwise), so both run on the same interpreter and libraries. The runs alternate, base then
this tree, so that a machine's drift falls on both; the table gives each median and the
ratio. The target (issue 44: a refactor of the layers above the kernel): within 3 % of the
base. ``--quick`` compares this tree with its own HEAD, one run each.
"""
import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_fill import ROOT, TEMPLATE, machine, warm_bytecode

TARGET_RATIO = 1.03
EXTENSIONS = ("airgun_xl/engine/_artsim.c", "airgun_xl/xlsx/_sheet_xml.c")


def _git(*args, cwd=ROOT):
    return subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True,
                          text=True).stdout


def checkout(base, tmp):
    """The base revision in ``tmp``/base, with this tree's compiled extensions."""
    for source in EXTENSIONS:
        if _git("show", f"{base}:{source}") != (ROOT / source).read_text():
            sys.exit(f"bench_revision: {source} differs at {base}; expected the same C "
                     "sources (compare a kernel change with bench_fill.py on each)")
    tree = tmp / "base"
    _git("worktree", "add", "--detach", str(tree), base)
    for built in ROOT.joinpath("airgun_xl").rglob("*.so"):
        shutil.copy(built, tree / built.relative_to(ROOT))
    for built in ROOT.joinpath("airgun_xl").rglob("*.pyd"):
        shutil.copy(built, tree / built.relative_to(ROOT))
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "airgun_xl")],
                   check=True)
    return tree


def _env(tree):
    return {"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin", "LANG": "C.UTF-8"}


def _imports_from(tree):
    """Refuse to time a tree whose package is not the one imported."""
    where = subprocess.run([sys.executable, "-c", "import airgun_xl; print(airgun_xl.__file__)"],
                           cwd=tree, env=_env(tree), check=True, capture_output=True,
                           text=True).stdout.strip()
    if not Path(where).is_relative_to(tree):
        sys.exit(f"bench_revision: {tree} imports airgun_xl from {where}")


def _run(tree, argv):
    """One command as a fresh process, the package imported from ``tree``; its wall time."""
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "airgun_xl", *argv], cwd=tree, check=True,
                   capture_output=True, env=_env(tree))
    return time.perf_counter() - started


def compare(trees, argv_of, repeat):
    """Alternating runs of each tree (after a warm-up of each): their medians [s]."""
    times = {name: [] for name in trees}
    for name, tree in trees.items():
        _run(tree, argv_of(name))
    for _ in range(repeat):
        for name, tree in trees.items():
            times[name].append(_run(tree, argv_of(name)))
    return {name: statistics.median(t) for name, t in times.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", default="HEAD")
    parser.add_argument("--repeat", type=int, default=9)
    parser.add_argument("--quick", action="store_true",
                        help="this tree against its own HEAD, one run each: shows the "
                             "benchmark runs, measures nothing")
    args = parser.parse_args()
    base, repeat, shots = ("HEAD", 1, 2) if args.quick else (args.base, args.repeat, 20)
    warm_bytecode()
    rows = [("benchmark", "base", "this tree", "ratio", "target")]
    with tempfile.TemporaryDirectory() as name:
        tmp = Path(name)
        tree = checkout(base, tmp)
        try:
            trees = {"base": tree, "this": ROOT}
            for path in trees.values():
                _imports_from(path)
            fill = compare(trees, lambda who: ["fill", str(TEMPLATE), "-o",
                                               str(tmp / f"{who}.xlsx"), "--force"], repeat)
            for who in trees:
                (tmp / f"day-{who}").mkdir()
                for k in range(shots):
                    shutil.copy(TEMPLATE, tmp / f"day-{who}" / f"shot_{k:03d}.xlsx")
            day = compare(trees, lambda who: ["fill", str(tmp / f"day-{who}"), "--jobs", "2",
                                              "--force"], max(1, repeat // 3))
        finally:
            _git("worktree", "remove", "--force", str(tree))
        for label, m, n in (("fill shot A, full output [s]", fill, 1),
                            (f"campaign of {shots}, --jobs 2 [s a shot]", day, shots)):
            ratio = m["this"] / m["base"]
            rows.append((label, f"{m['base'] / n:.3f}", f"{m['this'] / n:.3f}",
                         f"{ratio:.3f}", "not judged (--quick)" if args.quick else
                         f"<= {TARGET_RATIO}: {'met' if ratio <= TARGET_RATIO else 'NOT met'}"))
    print(f"machine: {machine()}")
    short = _git("rev-parse", "--short", base).strip()
    print("--quick: one repeat on a small case; these figures measure nothing\n" if args.quick
          else f"medians of {repeat} alternating runs after a warm-up (the campaign: "
               f"{max(1, repeat // 3)}); base {base} = {short}\n")
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    for r in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(r, widths, strict=True)))


if __name__ == "__main__":
    main()
