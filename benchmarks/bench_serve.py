"""Speed of `airgun-xl serve` (issue 48): ready, the shots page of a 10,000-entry archive, and
a shot's page with its 12,002-row pulse.

    python benchmarks/bench_serve.py [--repeat N] [--quick]

The archive: shot A filled once into a fresh archive, then its entry copied under 9,999 other
names (each copy's manifest and index row name it, its speed and peak varied), as a lab's
archive of that size would hold them; the copies are written directly, since 10,000 fills
would take most of an hour, and their large files are hard links to the first's (each entry
holds 5 MB: 50 GB otherwise). The server is started as a process, as a user starts it, and asked
over HTTP on the loopback. Reports:
- ready: from the process's start to its "serving" line (target: under 1 s);
- the shots page and a shot's page asked at once after the start, while the listing is read
  (the shots page says how far, 503; a shot's page answers from the index alone), the
  time until the runs are listed, and until every run's inputs are read;
- the shots page, the median of N requests once listed, unfiltered and filtered and sorted
  (target: under 300 ms on 2 cores), and drawn against an input the index does not hold;
- the CSV of the whole archive;
- a shot's page with its 12,002-row pulse (target: under 500 ms).
"""
import hashlib
import json
import os
import shutil
import sqlite3
import statistics
import subprocess
import sys
import time
import urllib.error
import urllib.request

from bench_fill import ROOT, TEMPLATE, judged, quick, run_table

ENTRIES = 10_000
TARGET_SHOTS = 0.300
TARGET_SHOT = 0.500
TARGET_READY = 1.0


def build_archive(tmp, entries):
    """An archive of ``entries`` entries: shot A filled once, copied for the others."""
    root = tmp / "archive"
    subprocess.run([sys.executable, "-m", "airgun_xl", "fill", str(TEMPLATE), "-o",
                    str(tmp / "a.xlsx"), "--archive", str(root), "--name", "a"],
                   check=True, capture_output=True)
    source = root / "a" / "v0001"
    summary = json.loads((source / "summary.json").read_text())
    manifest = json.loads((source / "manifest.json").read_text())
    with sqlite3.connect(root / "index.sqlite") as conn:
        conn.row_factory = sqlite3.Row
        first = dict(conn.execute("SELECT * FROM entries WHERE id = 1").fetchone())
        rows = []
        for k in range(2, entries + 1):
            name = f"bulk_{k:05d}"
            folder = root / name / "v0001"
            shutil.copytree(source, folder, copy_function=os.link)  # 5 MB an entry: shared
            for own in ("summary.json", "manifest.json"):  # these two its own
                (folder / own).unlink()
            v0 = 200.0 + (k * 37 % 1000) / 10.0
            peak = summary["peak_kg"] * (v0 / first["v0"]) ** 1.5
            text = json.dumps({**summary, "peak_kg": peak}).encode()
            (folder / "summary.json").write_bytes(text)
            index = {**manifest["index"], "shot": name, "v0": v0, "peak_kg": peak}
            files = {**manifest["files"], "summary.json": hashlib.sha256(text).hexdigest()}
            (folder / "manifest.json").write_text(json.dumps({**manifest, "index": index,
                                                              "files": files}))
            rows.append({**first, "id": k, "shot": name, "path": f"{name}/v0001", "v0": v0,
                         "peak_kg": peak})
        columns = list(first)
        conn.executemany(f"INSERT INTO entries ({', '.join(columns)}) VALUES "
                         f"({', '.join('?' for _ in columns)})",
                         [[r[c] for c in columns] for r in rows])
    return root


def start(root):
    """The server's process, its base URL and the seconds until it said it was ready."""
    started = time.perf_counter()
    process = subprocess.Popen([sys.executable, "-m", "airgun_xl", "serve", "--archive",
                                str(root), "--port", "0"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    line = process.stdout.readline()
    ready = time.perf_counter() - started
    if not line.startswith("serving "):
        process.kill()
        raise RuntimeError(f"serve did not start: {line!r} {process.stderr.read()}")
    return process, line.split(" at ", 1)[1].split(" ", 1)[0].rstrip("/"), ready


def fetch(url):
    """Seconds to read ``url`` whole, its body and its status."""
    started = time.perf_counter()
    try:
        with urllib.request.urlopen(url, timeout=120) as response:
            body, status = response.read(), response.status
    except urllib.error.HTTPError as exc:  # 503 while the listing is read
        body, status = exc.read(), exc.code
    return time.perf_counter() - started, body, status


def bench_serve(repeat, tmp):
    entries = 300 if quick() else ENTRIES
    root = build_archive(tmp, entries)
    readies, rows = [], []
    for _ in range(max(1, min(repeat, 5))):
        process, url, ready = start(root)
        readies.append(ready)
        process.terminate()
        process.wait(timeout=30)
    med = statistics.median(readies)
    rows.append(("serve ready (process start to its line)", "wall", f"{med:.3f} s",
                 f"target < {TARGET_READY:.0f} s: {judged(med < TARGET_READY)}"))
    started = time.perf_counter()
    process, url, _ready = start(root)
    try:
        # at once: the shots page says how far the listing's read is (503, a reload each
        # second); the time until it lists the runs
        first, _body, status = fetch(url + "/shots")
        rows.append(("shots page at once after the start", "wall", f"{first * 1e3:.0f} ms",
                     f"HTTP {status}; target < {TARGET_SHOTS * 1e3:.0f} ms: "
                     f"{judged(first < TARGET_SHOTS)}"))
        first, _body, status = fetch(url + "/shot/1")
        rows.append(("shot page at once after the start (from the index alone)", "wall",
                     f"{first * 1e3:.0f} ms", f"HTTP {status}; target < {TARGET_SHOT * 1e3:.0f} "
                     f"ms: {judged(first < TARGET_SHOT)}"))
        while fetch(url + "/shots.csv")[2] == 503:
            time.sleep(0.05)
        listed = time.perf_counter() - started
        rows.append((f"runs listed after the start, {entries:,} entries", "wall",
                     f"{listed:.2f} s", "the listing read once, in the background"))
        while fetch(url + "/shots.csv?input=A2")[2] == 503:
            time.sleep(0.05)
        listed = time.perf_counter() - started
        rows.append((f"every run's inputs read after the start, {entries:,} entries", "wall",
                     f"{listed:.2f} s", "then, in the background"))
        pages = [("shots page", "/shots", TARGET_SHOTS),
                 ("shots page, filtered and sorted",
                  "/shots?v0_min=220&v0_max=260&sort=peak_kg&desc=1&page=3", TARGET_SHOTS),
                 ("shots page, last page", "/shots?page=200", TARGET_SHOTS),
                 ("shots page, scatter against E43 (not indexed)", "/shots?x=E43",
                  TARGET_SHOTS),
                 ("CSV of every entry", "/shots.csv", None),
                 ("shot page (12,002-row pulse)", "/shot/1", TARGET_SHOT)]
        for label, path, target in pages:
            first, body, status = fetch(url + path)
            if status != 200:
                raise RuntimeError(f"{path}: HTTP {status}, expected 200")
            times = [fetch(url + path)[0] for _ in range(repeat)]
            med = statistics.median(times)
            verdict = (f"target < {target * 1e3:.0f} ms: {judged(med < target)}"
                       if target else f"{len(body) / 1e6:.1f} MB")
            rows.append((f"{label}, {entries:,} entries", "wall",
                         f"{med * 1e3:.0f} ms", f"first {first * 1e3:.0f} ms; {verdict}"))
    finally:
        process.terminate()
        process.wait(timeout=30)
    return rows


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT / "benchmarks"))
    run_table(__doc__, bench_serve)
