"""The exception tree of airgun-xl.

Every error a user can cause derives from :class:`AirgunXlError`. The CLI maps the whole tree to
exit code 2 and prints the message as one line; anything else is a bug and keeps its traceback.
All of them live here and are exported from :mod:`airgun_xl`. Library messages name the
argument (``force=True``); only the CLI names its flags.
"""


class AirgunXlError(Exception):
    """Base of every error airgun-xl raises on purpose; its message is one complete line."""

    exit_code = 2


class CellError(AirgunXlError):
    """A parameter cell holds something the run cannot use.

    Parameters
    ----------
    address : str
        The cell, e.g. ``"E2"``.
    label : str
        The cell's label in the legacy sheet, e.g. ``"Timestep"``.
    found : str
        What the cell holds, already formatted for the message.
    expected : str
        What it should hold.
    """

    def __init__(self, address, label, found, expected):
        self.address = address
        self.label = label
        self.found = found
        self.expected = expected
        super().__init__(f"{address} ({label}): found {found}, expected {expected}")


class WorkbookError(AirgunXlError):
    """A file is missing, unreadable, not a workbook, protected, or not in the report's layout."""


class OutputError(AirgunXlError):
    """The output cannot be written: it exists (without ``--force``) or its folder is unusable."""


class OptionError(AirgunXlError):
    """An option (a keyword of the Python API, a flag of the command line) has a value the
    command cannot use.

    Parameters
    ----------
    message : str
        The line, naming the keywords as the Python API spells them.
    template : str, optional
        The line with the keywords as ``{0}``, ``{1}``... (in ``fields``' order) and any
        other value as a named field of ``values``: the command line says it again with its
        flags (:func:`airgun_xl.cli.declared.flags_named`).
    fields : tuple of str
        The keywords the line names.
    values : dict
        The template's other fields.
    """

    def __init__(self, message, template=None, fields=(), values=None):
        super().__init__(message)
        self.template, self.fields, self.values = template, tuple(fields), dict(values or {})


class ResourceError(AirgunXlError):
    """A run would need more memory than the machine has (estimated before it starts)."""


class StabilityError(AirgunXlError):
    """The time step is above the scheme's critical step, or the run crushed past the length
    where it becomes unstable: the run would diverge or cannot be trusted."""


class DivergenceError(AirgunXlError):
    """The scheme diverged: a displacement became non-finite or passed the physical bound.

    Attributes
    ----------
    row : int
        The kernel's row index where it stopped (sheet row ``row + 2``).
    time : float
        Its time [s].
    values : dict
        The displacements Y1, Y31, Y32, Y33 at that row [m].
    cause : str or None
        What made it diverge, when known: ``"unloading quirk"`` (the macro's force jump at a
        second unloading) or None.
    """

    def __init__(self, message, row, time, values, cause=None):
        super().__init__(message)
        self.row, self.time, self.values, self.cause = row, time, values, cause


class DesignError(AirgunXlError):
    """The target cannot be met: it lies outside what the varied parameter can reach."""


class ArchiveError(AirgunXlError):
    """The archive cannot be used or does not hold what was asked for."""


class CampaignError(AirgunXlError):
    """Some shots of a campaign (``fill`` of many workbooks) failed; the others were filled.
    Each failure was said on its own line; this message counts them."""
