"""Every command's output, kept from before issue 44 moved the commands under ``app/``:
the documents' shell blocks (tests/docs_walk.py) and a line for each command they do not
show, run once in a fresh copy of the clone; for each line its exit code, its terminal text
and the workbooks it wrote.

``python tests/golden_commands.py`` writes tests/golden/commands.json (run it only where
the commands' output is meant to change, and say why in the commit);
tests/test_golden_commands.py runs the same lines and compares.

What is compared, and what differs from one run of the same code to the next and is
written as a name instead (found by running the walk twice, tests/test_golden_commands.py):

- the terminal text: the copy's folder is ``<clone>``; times of day (an entry's creation, a
  run's start) ``<date>``; measured run times (``in 5.2 s``, ``(135 runs, 0.75 s)``,
  ``(0.35 s a shot)``, show's ``started <date>, 0.05 s`` and ``run_seconds``, convergence's
  kernel and total seconds) ``<time>``; a sweep's shot-steps per second ``<rate>``;
  checksums ``<sha256>`` (an archived workbook's holds its run times); an entry's ``"id"``
  ``<id>`` (shots filled with ``--jobs`` are numbered in the order their workers end, which
  also orders their lines: a ``--jobs`` line's text is compared sorted, and so is
  history's, which lists the entries in the order they were archived);
- each workbook (.xlsx) written, as the SHA-256 of its parts uncompressed, in order: every
  sheet, chart and style as XlsxWriter or openpyxl wrote them (the zip's compression is
  zlib's, not ours), with its texts normalised as above, a fill's run times (its Summary's
  two rows of them; ``--reproducible`` leaves them out, the documents' fills do not give
  it) and convergence's time columns written 0, and the charts' caches of the sheets'
  numbers left out (the numbers are compared on the sheets);
- a workbook history writes by its rows' values, sorted (tests/golden_commands.row_digest);
- other files written (.csv, .json) by their bytes, a PNG by its being written (its bytes
  are matplotlib's version's); an archive's folders are not compared (their records hold
  the time they were made; show and history print them).
"""
import hashlib
import io
import json
import re
import subprocess
import sys
import zipfile
from pathlib import Path

from docs_walk import ROOT, runnable

GOLDEN = ROOT / "tests" / "golden" / "commands.json"

#: Lines for what the documents do not show: each command's help, the commands no block
#: runs, and a refusal of each kind (run after the documents' blocks, in the same copy).
COMMANDS = ("fill", "diff", "history", "show", "compare", "archive", "check", "convergence",
            "design", "sweep", "srs", "compare-measured", "calibrate", "accept", "next",
            "template")
EXTRA = (
    "airgun-xl --help",
    *(f"airgun-xl {command} --help" for command in COMMANDS),
    "airgun-xl fill templates/shot_a.xlsx -o lab/golden_fill.xlsx --force --reproducible",
    "airgun-xl fill templates/shot_a.xlsx -o lab/golden_only.xlsx --force --reproducible "
    "--only summary --peak 8.6kG:10% --duration 5.25ms:10%",
    "airgun-xl check templates/shot_a.xlsx",
    "airgun-xl convergence templates/shot_a.xlsx --levels 10us,5us,2us -o lab/golden_conv.xlsx "
    "--force",
    "airgun-xl srs templates/shot_a.xlsx -o lab/golden_srs.xlsx --force",
    "airgun-xl compare-measured templates/shot_a.xlsx templates/shot_a_recording.csv "
    "--sign -1 --cfc 1000 -o lab/golden_cm.xlsx --force",
    "airgun-xl accept templates/shot_a.xlsx templates/shot_a_recording.csv --sign -1 "
    "--peak 9.5kG:10% --duration 5ms:15% -o lab/golden_accept.xlsx --force",
    "airgun-xl design templates/shot_a.xlsx --target-peak 8kG -o lab/golden_design.xlsx "
    "--force",
    "airgun-xl sweep templates/shot_a.xlsx --vary A28=150:250:3 -o lab/golden_sweep.xlsx "
    "--force",
    "airgun-xl history --archive lab/shots --json",
    "airgun-xl show shot_17@1 --archive lab/shots --json",
    "airgun-xl template lab/golden_template.xlsx --force",
    # refusals: one line each, exit 2
    "airgun-xl fill lab/no_such.xlsx",
    "airgun-xl fill templates/shot_a.xlsx --forse",
    "airgun-xl accept templates/shot_a.xlsx templates/shot_a_recording.csv --peak 12KG",
    "airgun-xl design templates/shot_a.xlsx --crush-law LOT-2026-07",
    "airgun-xl sweep templates/shot_a.xlsx --vary A28=1:2:0",
    "airgun-xl srs templates/shot_a.xlsx --srs-q 0",
    "airgun-xl calibrate templates/shot_a.xlsx",
)

#: A measured time: "in" a number and a unit of time ("805 shots in 5.2 s"); a rate of
#: work per second.
_TIME = re.compile(r"\bin \d+(?:\.\d+)? ?(?:s|ms|min)\b")
_RATE = re.compile(r"\b[\d.]+(?:e[+-]?\d+)? shot-steps/s")
#: A time of day (ISO 8601): an archive entry's creation, a run's start.
_DATE = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(?:\.\d+)?(?:[+-]\d\d:\d\d|Z)?")
#: A SHA-256 in the terminal text (show's checksums of files that hold run times).
_SHA = re.compile(r"\b[0-9a-f]{64}\b")
#: An entry's number in its index: shots filled with --jobs are numbered in the order their
#: workers end.
_ID = re.compile(r'("id": )\d+')
#: A measured duration in a JSON document (show --json's provenance).
_SECONDS = re.compile(r'("(?:run|kernel)_seconds": )[0-9.eE+-]+')

#: Measured run times in the terminal text: calibrate's "(135 runs, 0.75 s)", a
#: campaign's "(0.35 s a shot)", show's provenance ("started <date>, 0.05 s"), convergence's
#: table's kernel and total seconds.
_RUN_TIMES = (
    (re.compile(r"(\d runs, )\d+(?:\.\d+)? s\)"), r"\1<time>)"),
    (re.compile(r"\(\d+(?:\.\d+)? s a shot\)"), "(<time> a shot)"),
    (re.compile(r"(started <date>, )\d+(?:\.\d+)? s\b"), r"\1<time>"),
    (re.compile(r"(?m)^(\s+\S+\s+[\d,]+\s+)\d+\.\d+(\s+)\d+\.\d+(?=\s+\d)"),
     r"\1<time>\2<time>"),
)

#: The labels (column A) of the Summary rows that hold a fill's run times [s], and the
#: headers (row 1) of the columns that hold convergence's.
TIMED_LABELS = ("Kernel run time", "Run time")
TIMED_HEADERS = ("Kernel time (s)", "Total time (s)")


def lines():
    """(document, line) of every command the walk runs, in order."""
    out = []
    for name, block in runnable():
        for line in block.splitlines():
            if line.strip() and not line.lstrip().startswith("#"):
                out.append((name, line))
    return out + [("golden", line) for line in EXTRA]


def normalise(text, work):
    """``text`` with what differs from run to run of the same code written as a name."""
    text = text.replace(str(work), "<clone>")
    text = _SECONDS.sub(r"\1<time>", _SHA.sub("<sha256>", _DATE.sub("<date>", text)))
    text = _ID.sub(r"\1<id>", text)
    for pattern, written in _RUN_TIMES:
        text = pattern.sub(written, text)
    return _TIME.sub("in <time>", _RATE.sub("<rate>", text))


def _strings(part):
    """A sheet's or the shared strings' texts, normalised (dates and times)."""
    return re.sub(rb"(<t(?:\s[^>]*)?>)(.*?)(</t>)", lambda m: m[1] + normalise(
        m[2].decode(), Path("/nonexistent")).encode() + m[3], part, flags=re.S)


_NUMBER_CELL = rb'(<c r="%s\d+"(?:(?!t=")[^>])*>)<v>[^<]*</v>'


def _timed(part, rows, columns):
    """A sheet with the numbers of every row labelled (column A) with a shared string in
    ``rows``, and of every column headed (row 1) with one in ``columns``, written as 0."""
    def shared(pattern, indices):
        return [m for m in re.finditer(pattern, part) if int(m[2]) in indices]

    for m in shared(rb'<c r="([A-Z]+)1"[^>]*t="s"[^>]*><v>(\d+)</v>', columns):
        part = re.sub(_NUMBER_CELL % m[1], rb"\1<v>0</v>", part)

    def row(m):
        label = re.search(rb'<c r="A\d+"[^>]*t="s"[^>]*><v>(\d+)</v>', m[0])
        if label and int(label[1]) in rows:
            return re.sub(_NUMBER_CELL % rb"[B-Z]", rb"\1<v>0</v>", m[0])
        return m[0]
    return re.sub(rb"<row [^>]*>.*?</row>", row, part, flags=re.S) if rows else part


def _used(part):
    """The shared strings a sheet shows."""
    return {int(k) for k in re.findall(rb't="s"[^>]*><v>(\d+)</v>', part)}


def digest(path):
    """SHA-256 of a workbook's parts uncompressed, in order, normalised (else of the file's
    bytes)."""
    h = hashlib.sha256()
    data = path.read_bytes()
    if path.suffix == ".png":  # matplotlib's bytes are its version's: that it was written
        return "png"
    if path.suffix != ".xlsx":
        h.update(data)
        return h.hexdigest()
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        names = z.namelist()
        strings = z.read("xl/sharedStrings.xml") if "xl/sharedStrings.xml" in names else b""
        texts = [re.sub(rb"<[^>]+>", b"", si).decode() for si in
                 re.findall(rb"<si>(.*?)</si>", strings, re.S)]
        rows = {k for k, t in enumerate(texts) if t in TIMED_LABELS}
        columns = {k for k, t in enumerate(texts) if t in TIMED_HEADERS}
        for name in names:
            part = z.read(name)
            if name == "xl/sharedStrings.xml" or (name.startswith("xl/worksheets/")
                                                  and b"<is>" in part):
                part = _strings(part)
            if name.startswith("xl/charts/"):  # the cache repeats the sheets' numbers
                part = re.sub(rb"<c:numCache>.*?</c:numCache>", b"", part, flags=re.S)
                # and an axis's decades follow its data: convergence's run-time axis moves
                # from 1e-3 to 1e-4 s as a run is a little faster (seen once in 6 runs)
                part = re.sub(rb'<c:(min|max) val="[^"]*"/>', rb"<c:\1/>", part)
            if name.startswith("xl/worksheets/") and any(
                    f't="s"><v>{k}</v>'.encode() in part for k in rows | columns):
                part = _timed(part, rows & _used(part), columns)
            h.update(name.encode() + b"\0" + part)
    return h.hexdigest()


def row_digest(path):
    """SHA-256 of a workbook's sheets' rows, each row's values normalised, the rows sorted:
    for what history writes, whose rows come in the order the shots were archived (by
    ``fill --jobs``, the order its workers end)."""
    import datetime

    import openpyxl

    h = hashlib.sha256()
    book = openpyxl.load_workbook(path, read_only=True)
    try:
        for sheet in book.worksheets:
            rows = sorted(repr(tuple(
                "<date>" if isinstance(v, datetime.datetime) else
                normalise(v, Path("/nonexistent")) if isinstance(v, str) else v for v in row))
                for row in sheet.iter_rows(values_only=True))
            h.update(sheet.title.encode() + b"\0" + "\n".join(rows).encode())
    finally:
        book.close()
    return "rows " + h.hexdigest()


def _files(work):
    """{relative path: digest} of what the commands write (lab/, outside archives)."""
    out = {}
    lab = work / "lab"
    if not lab.exists():
        return out
    archives = {p.parent for p in lab.rglob(".airgun-xl-archive")}
    for path in sorted(lab.rglob("*")):
        if (path.is_file() and path.suffix in (".xlsx", ".csv", ".json", ".png")
                and not any(a in path.parents for a in archives)):
            out[str(path.relative_to(work))] = digest(path)
    return out


def walk(work, env, before_extra=None):
    """Run every line in ``work``: [{line, code, stdout, stderr, files}] in order;
    ``before_extra`` is called once the documents' lines have run, before the first of
    :data:`EXTRA`."""
    records = []
    before = _files(work)
    for name, line in lines():
        if name == "golden" and before_extra is not None:
            before_extra()
            before_extra = None
        done = subprocess.run(["bash", "-c", line], cwd=work, env=env, capture_output=True,
                              text=True, timeout=600)
        after = _files(work)
        out, err = normalise(done.stdout, work), normalise(done.stderr, work)
        files = {k: v for k, v in after.items() if before.get(k) != v}
        # the shots' lines come in the order fill --jobs's workers end, and history lists
        # the entries in the order they were archived
        if "--jobs" in line or line.startswith("airgun-xl history"):
            out, err = ("".join(sorted(t.splitlines(keepends=True))) for t in (out, err))
        if line.startswith("airgun-xl history"):
            files = {k: row_digest(work / k) if k.endswith(".xlsx") else v
                     for k, v in files.items()}
        records.append({"document": name, "line": line, "code": done.returncode,
                        "stdout": out, "stderr": err, "files": files})
        before = after
    return records


def main():
    import tempfile

    sys.path.insert(0, str(ROOT / "tests"))
    from docs_walk import workspace

    with tempfile.TemporaryDirectory() as tmp:
        work, env = workspace(Path(tmp))
        records = walk(work, env)
    GOLDEN.parent.mkdir(exist_ok=True)
    GOLDEN.write_text(json.dumps(records, indent=1, ensure_ascii=False) + "\n")
    print(f"wrote {GOLDEN.relative_to(ROOT)}: {len(records)} lines")


if __name__ == "__main__":
    main()
