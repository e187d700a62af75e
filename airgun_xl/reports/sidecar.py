"""The full time history beside the workbook: Parquet (pyarrow), or CSV without it."""
from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..result import FRAME_UNITS
from ..transaction import atomic_path, display

#: The sidecar's name beside ``run.xlsx``: ``run`` + one of these.
SIDECAR_SUFFIXES = (".history.parquet", ".history.csv")


def have_parquet():
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def sidecar_path(output, parquet=None):
    """``run.xlsx`` -> ``run.history.parquet`` (or ``.csv`` without pyarrow)."""
    output = Path(output)
    parquet = have_parquet() if parquet is None else parquet
    return output.with_name(output.stem + SIDECAR_SUFFIXES[0 if parquet else 1])


def write_history(result, path, force=False):
    """Write every row of every per-row series of ``result`` to ``path``, atomically."""
    with atomic_path(path, force) as tmp:
        render_history(result, tmp, shown=path)
    return path


def render_history(result, tmp, shown=None):
    """Write every row of every per-row series of ``result`` into the file ``tmp``.

    Columns are those of :meth:`Result.to_frame` with the time first, units in the Parquet
    schema metadata (or in the CSV header as ``name [unit]``). Series that were not tracked
    are left out. The format follows ``tmp``'s final name: ``.parquet`` or ``.csv``.

    Raises
    ------
    airgun_xl.errors.OutputError
        When the file cannot be written (a full disk, a file-size limit).
    """
    shown = Path(shown if shown is not None else tmp)
    columns = {"time": result.history.time}
    for name, values in result.frame_columns().items():
        if values is not None:
            columns[name] = values
    units = dict(FRAME_UNITS, time="s")
    try:
        if shown.suffix == ".parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            table = pa.Table.from_arrays([_arrow_column(pa, v) for v in columns.values()],
                                         names=list(columns))
            table = table.replace_schema_metadata({f"unit:{k}": units[k] for k in columns})
            # dictionary encoding of float columns costs 1 s on 1.2M rows and saves nothing
            pq.write_table(table, str(tmp), use_dictionary=False)
        else:
            header = ",".join(f"{k} [{units[k]}]" for k in columns)
            data = np.column_stack(list(columns.values()))
            np.savetxt(tmp, data, delimiter=",", header=header, comments="", fmt="%.17g")
    except OSError as exc:  # pyarrow's ArrowIOError is an OSError too
        raise OutputError(f"{display(shown)}: cannot be written "
                          f"({exc.strerror or str(exc).splitlines()[0]})") from None


def _arrow_column(pa, values):
    """A float64 Arrow array over the numpy buffer, without a copy. (``pa.array`` would do the
    same but imports pandas to check its argument: 0.4 s of a fill's start.) NaN stays NaN, as
    with ``pa.array``."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), len(values), [None, pa.py_buffer(values)])
