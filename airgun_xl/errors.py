"""The exception tree of airgun-xl.

Every error a user can cause derives from :class:`AirgunXlError`. The CLI maps the whole tree to
exit code 2 and prints the message as one line; anything else is a bug and keeps its traceback.
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
    """A command-line option has a value the command cannot use."""


class ResourceError(AirgunXlError):
    """A run would need more memory than the machine has (estimated before it starts)."""
