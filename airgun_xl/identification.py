"""The test a verdict is of (issue 63): who asked for it, what was tested, who fired it, where
and when. A client signs a report that names its test; a report that does not is sent back.

The fields come from the Specification sheet's *Test* block (columns I and J:
:data:`airgun_xl.readers.spec_sheet.TEST_FIRST_ROW`) and from options (``--client``,
``--test-id``, ``--item``, ``--serial``, ``--operator``, ``--lab``): an option given wins over
the sheet's value, and the verdict says so. Every field is text (a number or a date in a cell
is shown as the cell holds it), kept as text wherever it is written (never a formula), at most
:data:`MAX_CHARS` characters. A field given by no source is printed as a blank line to fill by
hand, never left out.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

#: (field, label) in the order a report prints them.
FIELDS = (("client", "Client"), ("test_id", "Test number"), ("item", "Test item"),
          ("serial", "Serial number"), ("lot", "Lot"), ("operator", "Operator"),
          ("lab", "Laboratory"), ("date", "Date of the test"),
          ("velocity", "Velocity measured"))

#: The fields an option gives, and its flag.
FLAGS = {"client": "--client", "test_id": "--test-id", "item": "--item",
         "serial": "--serial", "operator": "--operator", "lab": "--lab"}

#: The longest text a field keeps [characters]: a page's line.
MAX_CHARS = 120

#: What a report prints for a field no source gave: a line to write on.
BLANK = "_" * 20

LABELS = dict(FIELDS)


@dataclass(frozen=True)
class Identification:
    """The test's fields (``values``: field -> text, only those given) and what the merge
    said (``notes``: an option over the sheet's value)."""

    values: Mapping[str, str] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @classmethod
    def merged(cls, sheet: Mapping[str, str], options: Mapping[str, str | None]
               ) -> Identification:
        """The sheet's fields with the options' over them, each replacement said."""
        values = dict(sheet)
        notes = []
        for name, value in options.items():
            if value is None:
                continue
            if name in sheet and sheet[name] != value:
                notes.append(f"test: {FLAGS[name]} {value!r} replaces the Specification "
                             f"sheet's {LABELS[name].lower()}, {sheet[name]!r}")
            values[name] = value
        return cls(values, tuple(notes))

    def rows(self) -> list[tuple[str, str]]:
        """(label, text) for every field, a blank line for those not given."""
        return [(label, self.values.get(name) or BLANK) for name, label in FIELDS]

    def given(self) -> dict[str, str]:
        """The fields given, as a record keeps them."""
        return {name: self.values[name] for name, _ in FIELDS if self.values.get(name)}


def text_of(value: object) -> str:
    """A cell's or an option's value as a field's text: printable, on one line, cut to
    :data:`MAX_CHARS` (a date as its ISO day; a whole number without its point)."""
    import datetime

    from .untrusted_json import printable

    if isinstance(value, datetime.datetime):
        text = value.date().isoformat() if value.time() == datetime.time() else \
            value.isoformat(sep=" ", timespec="minutes")
    elif isinstance(value, datetime.date):
        text = value.isoformat()
    elif isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        text = str(int(value))
    else:
        text = str(value)
    text = " ".join(printable(text).split())
    return text if len(text) <= MAX_CHARS else text[:MAX_CHARS - 3] + "..."
