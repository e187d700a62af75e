"""The caps that keep an untrusted file, option or run from taking the machine down.

Every cap is checked before the work it bounds starts, and each refusal is one line naming the
file, cell or option, what was found and what is expected. docs/security.md
lists them; this module is the one place that holds the numbers.
"""

#: Largest workbook file read [bytes]. Shot workbooks are ~10 kB and a legacy output at the
#: macro's 32,767-row limit ~4 MB; anything past this is refused before a parser sees it.
MAX_INPUT_BYTES = 50 * 2**20

#: Most members in an .xlsx/.xlsm zip (a workbook has ~10-30).
MAX_ZIP_MEMBERS = 1_000

#: Largest inflated size of a zip member that is parsed whole (workbook, styles, shared
#: strings, relationships, properties) [bytes]. A shot's are a few kB and Excel's styles a few
#: hundred; openpyxl builds each into Python objects (twice: formulas, then cached values),
#: ~5 s and ~150 MB for 4 MB of distinct styles or strings.
MAX_MEMBER_BYTES = 4 * 2**20

#: Largest inflated size of the whole package [bytes]. Worksheets are streamed, and only their
#: first rows are read by ``fill``; a 1M-row legacy sheet inflates to ~500 MB.
MAX_INFLATED_BYTES = 2 * 2**30

#: Largest inflation ratio of a member over 1 MB. Spreadsheet XML deflates 3-15x; a zip bomb
#: of whitespace 1000x.
MAX_RATIO = 200
RATIO_FLOOR_BYTES = 2**20

#: Rows of the parameter sheet (and of any sheet its formulas name) that ``fill`` reads. The
#: report's block ends at row 43; references past this fail like unsupported formulas.
BLOCK_ROWS = 200

#: Most cells (rows x columns of the first sheet's real extent) ``diff`` reads from one
#: workbook. The macro's 32,767-row limit x 28 columns is 0.92 M; python-calamine holds the
#: extent densely at 32 bytes a cell, so 4 M cells stay ~130 MB.
MAX_DIFF_CELLS = 4_000_000

#: Most cells of an .xls sheet's real extent that is read (the format allows 65,536 x 256).
MAX_XLS_CELLS = MAX_DIFF_CELLS

#: Memory budget of any command reading an input under MAX_INPUT_BYTES [bytes].
READ_BUDGET_BYTES = 500 * 2**20

#: Largest N of ``--every``: more than the most rows a run may have (cells.MAX_STEPS + 2).
MAX_EVERY = 10**9

#: Most shots of one sweep or Monte Carlo run.
MAX_SHOTS = 10**7

#: Largest recording file a format that reads a window of a channel (ASAM MDF) opens [bytes]:
#: such a file is never read whole, only its metadata and the stretch of the chosen channel
#: around its pulse (a 20 GB export of many channels is usual); every other file stays under
#: MAX_INPUT_BYTES.
MAX_WINDOWED_BYTES = 256 * 2**30

#: Most samples a measured recording may hold: 40 s at 50 kHz, 32 MB as two float columns.
MAX_SAMPLES = 2_000_000

#: Monte Carlo draws a setting of ``design --confidence`` and ``next`` (--shots): a
#: P(PASS) to +/- 0.0003 at a million; more only costs minutes and memory.
MIN_DRAWS, MAX_DRAWS = 100, 10**6

#: Largest seed of a study's draws (numpy's SeedSequence takes any whole number >= 0).
MAX_SEED = 2**128 - 1

#: The smallest peak a recording may have to be judged [kG] (about 0.001 g): below it there
#: is no shock to measure, and a record of subnormal numbers (5e-324) breaks every ratio.
MIN_RECORDED_PEAK_KG = 1e-6

#: A recording's sample step, in every format [s]: at most 1 GHz (no shock recorder samples
#: faster; the SRS's decimation keeps a rest of 16 x 1/(40 x f x dt) samples, 320 MB at
#: 1 THz) and at least 1 Hz (a pulse of milliseconds has no sample at a slower rate).
MIN_SAMPLE_STEP = 1e-9
MAX_SAMPLE_STEP = 1.0

#: Most octaves an SRS spans (12 natural frequencies an octave): 1 Hz to 1 GHz is 30.
MAX_SRS_OCTAVES = 40


# -- memory, estimated before a run -------------------------------------------------------------
#: Environment variable that sets the memory a command may plan to use, e.g. ``2GB``; by default
#: the machine's available memory (MemAvailable, or a cgroup's limit when lower).
MEMORY_ENV = "AIRGUN_XL_MEMORY"

#: Resident size of a fill process before its run: Python, numpy, pandas, openpyxl, xlsxwriter
#: [bytes]. Measured 144-150 MB by extrapolating fills of 1.2 M and 3 M rows to zero rows.
BASE_BYTES = 200 * 2**20

#: Bytes a time row costs a fill beyond the tracked step values: time and four displacements,
#: the derived acceleration columns and their temporaries (FFT, decimation). Measured 137-140
#: B/row with no tracked series (``--only positions``, ``--only summary``), 184 with all 8.
ROW_BYTES = 144

#: Bytes a shot costs a sweep: its parameters, values and figures. Measured ~1 KB.
SHOT_BYTES = 1_100


def parse_bytes(text):
    """``"2GB"``, ``"500 MB"``, ``"1.5e9"`` -> bytes; None when not a size."""
    import re

    m = re.fullmatch(r"\s*([0-9.eE+]+)\s*([KMGT]?i?B?)?\s*", str(text), re.IGNORECASE)
    if not m:
        return None
    try:
        value = float(m.group(1))
    except ValueError:
        return None
    unit = (m.group(2) or "").upper().rstrip("B").rstrip("I")
    scale = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}[unit]
    size = value * scale
    return int(size) if 0 < size < 2**63 else None  # 1e999 is inf: not a size (23.14)


def available_memory():
    """Bytes a command may plan to use: $AIRGUN_XL_MEMORY, else MemAvailable (Linux), lowered
    to the cgroup's limit when there is one; None when unknown (no check)."""
    import os

    given = os.environ.get(MEMORY_ENV)
    if given:
        value = parse_bytes(given)
        if value is None:
            from .errors import OptionError

            raise OptionError(f"${MEMORY_ENV}: found {given!r}, expected a size such as 2GB")
        return value
    found = []
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    found.append(int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    try:
        with open("/sys/fs/cgroup/memory.max") as fh:
            text = fh.read().strip()
        if text.isdigit():
            with open("/sys/fs/cgroup/memory.current") as fh:
                found.append(int(text) - int(fh.read().strip()))
    except (OSError, ValueError):
        pass
    found += address_space_left()
    return min(found) if found else None


def address_space_left():
    """[bytes] the process may still map under ``ulimit -v`` (RLIMIT_AS), less what it has
    mapped; [] where there is no such limit (or no ``resource`` module: Windows)."""
    try:
        import resource
    except ImportError:
        return []
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY or soft <= 0:
        return []
    mapped = 0
    try:
        with open("/proc/self/statm") as fh:  # Linux: pages mapped now
            import os

            mapped = int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError, AttributeError):
        pass
    return [max(0, soft - mapped)]


def fill_bytes(rows, tracked, csv_sidecar=False):
    """Peak memory of a fill of ``rows`` time rows recording ``tracked`` step values [bytes]."""
    per_row = ROW_BYTES + 8 * tracked + (8 * (6 + tracked) * 3 if csv_sidecar else 0)
    return BASE_BYTES + rows * per_row


def sweep_bytes(shots, rows, threads=2, block=128):
    """Peak memory of a sweep of ``shots`` shots of ``rows`` rows [bytes]."""
    return BASE_BYTES + shots * SHOT_BYTES + threads * block * rows * 8 * 6


def check_memory(needed, what, way_out):
    """Refuse a run whose estimate ``needed`` passes the available memory.

    Raises
    ------
    airgun_xl.errors.ResourceError
        Naming the figure, the memory available and ``way_out``.
    """
    available = available_memory()
    if available is not None and needed > available:
        from .errors import ResourceError

        raise ResourceError(f"{what} needs about {needed / 2**30:,.2f} GB, more than the "
                            f"{available / 2**30:,.2f} GB available; expected {way_out}")


#: The largest acceleration a recording may hold [kG] (10^9 g): past it a sample is no
#: recorder's (a 1e200 spike would overflow the noise's square); refused, naming its time.
MAX_RECORD_KG = 1e6

#: The most SDOF filter steps an SRS criterion may take (requirement rows x record samples):
#: about 2 s on one core. 2,000 rows over a 2,000,000-sample record would be 4e9 (a minute
#: and more); refused before any is run, naming --srs.
MAX_SRS_STEPS = 200_000_000
