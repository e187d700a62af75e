"""Checks on an untrusted workbook before any parser sees it.

A workbook may come from anyone. Before openpyxl or python-calamine runs, this module:

- opens the path without blocking and refuses anything but a regular file (a FIFO, a device
  such as ``/dev/zero``, a folder) and files past :data:`~airgun_xl.limits.MAX_INPUT_BYTES`;
- checks an .xlsx/.xlsm zip: member count, each member's inflated size and inflation ratio,
  the total; every XML member that is parsed whole goes through defusedxml first (no DTD, no
  entities, no external references);
- measures a worksheet's real extent (the cells it holds, not its ``<dimension>`` tag, which may
  lie) with a defusedxml SAX pass, and an .xls sheet's extent from its BIFF cell records,
  because python-calamine allocates the whole extent densely.

Each refusal is a :class:`~airgun_xl.errors.WorkbookError` of one line.
"""
import io
import os
import posixpath
import stat
import struct
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

from .. import limits
from ..errors import WorkbookError
from ..transaction import display, special_kind

ZIP_MAGIC = b"PK\x03\x04"
CFB_MAGIC = bytes.fromhex("D0CF11E0A1B11AE1")  # OLE compound file: .xls, or an encrypted .xlsx
ENCRYPTED_STREAM = "EncryptedPackage".encode("utf-16-le")
EXPECTED = "expected a workbook (.xlsx, .xlsm or .xls)"

#: What reading a zip member can raise on damaged bytes: zipfile reports a bad CRC as
#: BadZipFile, but a broken deflate stream as zlib.error.
_READ_ERRORS = (zipfile.BadZipFile, OSError, EOFError, ValueError, zlib.error)

def _mib(n):
    return f"{n / 2**20:,.1f} MB"


def _open(path, expected, what, follow):
    """A descriptor of the regular file at ``path`` and its status, opened without blocking
    (``follow`` False: a symlink refused at the open itself, where the platform can)."""
    shown = display(Path(path))
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0)
                     | getattr(os, "O_BINARY", 0)
                     | (0 if follow else getattr(os, "O_NOFOLLOW", 0)))
    except FileNotFoundError:
        raise WorkbookError(f"{shown}: no such file, {expected}") from None
    except IsADirectoryError:
        raise WorkbookError(f"{shown}: is a folder, {expected}") from None
    except OSError as exc:
        raise WorkbookError(f"{shown}: cannot be read ({exc.strerror}), {expected}") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise WorkbookError(f"{shown}: is a folder, {expected}")
        kind = special_kind(st.st_mode)
        if kind is not None:
            raise WorkbookError(f"{shown}: is {kind}, expected a regular {what} file")
    except OSError as exc:
        os.close(fd)
        raise WorkbookError(f"{shown}: cannot be read ({exc.strerror}), {expected}") from None
    except WorkbookError:
        os.close(fd)
        raise
    return fd, st


def read_bytes(path, expected=EXPECTED, what="workbook", head=None, follow=True):
    """The bytes of a regular file, read without blocking and capped at MAX_INPUT_BYTES; with
    ``head``, its first ``head`` bytes only, whatever its size (a format told by content);
    ``follow`` False refuses a symlink at the open itself (no check-then-open race), where
    the platform can (``O_NOFOLLOW``).

    Raises
    ------
    WorkbookError
        When the path is missing, not a regular file (a FIFO, a device, a folder), larger
        than the cap, or unreadable; ``expected`` ends each message.
    """
    path = Path(path)
    shown = display(path)
    fd, st = _open(path, expected, what, follow)
    try:
        if head is not None:
            with os.fdopen(os.dup(fd), "rb") as fh:
                return fh.read(head)
        if st.st_size > limits.MAX_INPUT_BYTES:
            raise WorkbookError(f"{shown}: is {_mib(st.st_size)}, expected a {what} of at most "
                                f"{_mib(limits.MAX_INPUT_BYTES)}")
        with os.fdopen(os.dup(fd), "rb") as fh:
            data = fh.read(limits.MAX_INPUT_BYTES + 1)
    except OSError as exc:
        raise WorkbookError(f"{shown}: cannot be read ({exc.strerror}), {expected}") from None
    finally:
        os.close(fd)
    if len(data) > limits.MAX_INPUT_BYTES:  # it grew while being read
        raise WorkbookError(f"{shown}: is larger than {_mib(limits.MAX_INPUT_BYTES)}, expected "
                            f"a smaller {what}")
    return data


@dataclass(frozen=True)
class LargeFile:
    """A regular file too large to read whole, known by its identity (device, inode, size) so
    that whoever opens it later opens this file and no other (:func:`open_large`)."""

    path: str
    device: int
    inode: int
    size: int


def large_file(path, expected, what, cap):
    """The :class:`LargeFile` at ``path`` (a regular file, no symlink, at most ``cap``
    bytes), or None when it is small enough for :func:`read_bytes`.

    Raises
    ------
    WorkbookError
        As :func:`read_bytes`, and past ``cap``.
    """
    fd, st = _open(path, expected, what, follow=False)
    os.close(fd)
    if st.st_size <= limits.MAX_INPUT_BYTES:
        return None
    if st.st_size > cap:
        raise WorkbookError(f"{display(Path(path))}: is {_mib(st.st_size)}, expected a {what} "
                            f"of at most {_mib(cap)}")
    return LargeFile(str(path), st.st_dev, st.st_ino, st.st_size)


def open_large(large):
    """The :class:`LargeFile` opened for reading, a binary file object; an error when the path
    no longer names that very file (replaced, grown, or a symlink put in its place)."""
    fd, st = _open(large.path, "expected the file it was", "recording", follow=False)
    if (st.st_dev, st.st_ino, st.st_size) != (large.device, large.inode, large.size):
        os.close(fd)
        raise WorkbookError(f"{display(Path(large.path))}: changed while it was read, expected "
                            "the file as it was")
    return os.fdopen(fd, "rb")


def read_input(path):
    """The bytes of a workbook file and its kind, ``"zip"`` or ``"xls"``.

    Raises
    ------
    WorkbookError
        When the path is missing, not a regular file, larger than the cap, unreadable, not a
        workbook, or password-protected.
    """
    shown = display(Path(path))
    data = read_bytes(path)
    if data.startswith(ZIP_MAGIC):
        return data, "zip"
    if data.startswith(CFB_MAGIC):
        if ENCRYPTED_STREAM in data:
            raise WorkbookError(f"{shown}: is password-protected, expected an unprotected "
                                "workbook (save a copy without a password)")
        return data, "xls"
    raise WorkbookError(f"{shown}: is not a workbook, {EXPECTED}")


# -- .xlsx / .xlsm -----------------------------------------------------------------------------
def _streamed(name):
    """Members read as a stream (worksheets), so only the inflation ratio bounds them."""
    return name.startswith("xl/worksheets/") and name.endswith(".xml")


def _parsed_whole(name):
    return name.endswith((".xml", ".rels", ".vml")) and not _streamed(name)


def open_zip(path, data):
    """A checked :class:`zipfile.ZipFile` over ``data``; every whole-parsed XML member passed
    through defusedxml.

    Raises
    ------
    WorkbookError
    """
    shown = display(path)
    try:
        zf = zipfile.ZipFile(io.BytesIO(data))
        members = zf.infolist()
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, OSError) as exc:
        raise WorkbookError(f"{shown}: is not a readable .xlsx workbook ({exc})") from None
    if len(members) > limits.MAX_ZIP_MEMBERS:
        raise WorkbookError(f"{shown}: holds {len(members):,} zip members, expected a workbook "
                            f"of at most {limits.MAX_ZIP_MEMBERS:,}")
    total = 0
    for m in members:
        total += m.file_size
        if m.file_size > limits.RATIO_FLOOR_BYTES and (
                m.file_size > limits.MAX_RATIO * max(m.compress_size, 1)):
            raise WorkbookError(
                f"{shown}: member {m.filename} inflates {m.compress_size:,} bytes to "
                f"{m.file_size:,} ({m.file_size / max(m.compress_size, 1):,.0f}x), expected at "
                f"most {limits.MAX_RATIO}x (a zip bomb?)")
        if _parsed_whole(m.filename) and m.file_size > limits.MAX_MEMBER_BYTES:
            raise WorkbookError(f"{shown}: member {m.filename} inflates to "
                                f"{_mib(m.file_size)}, expected at most "
                                f"{_mib(limits.MAX_MEMBER_BYTES)}")
    if total > limits.MAX_INFLATED_BYTES:
        raise WorkbookError(f"{shown}: inflates to {_mib(total)}, expected a workbook of at "
                            f"most {_mib(limits.MAX_INFLATED_BYTES)} inflated")
    for m in members:
        if _parsed_whole(m.filename):
            _defused(shown, zf, m)
        elif _streamed(m.filename):
            _defused_prolog(shown, zf, m)
    return zf


def _declares(shown, member, exc):
    return WorkbookError(f"{shown}: member {member} declares a DTD or entities "
                         f"({type(exc).__name__}), expected plain spreadsheet XML")


def _defused_prolog(shown, zf, member, size=1 << 16):
    """A streamed worksheet's first bytes through defusedxml: a DTD or an entity declaration
    sits in the prolog, before any cell."""
    import defusedxml
    from defusedxml.ElementTree import DefusedXMLParser, ParseError

    try:
        with zf.open(member) as fh:
            head = fh.read(size)
        DefusedXMLParser(forbid_dtd=True).feed(head)
    except defusedxml.DefusedXmlException as exc:
        raise _declares(shown, member.filename, exc) from None
    except ParseError:
        pass  # a malformed sheet is reported by the parser that reads it
    except _READ_ERRORS as exc:
        raise WorkbookError(f"{shown}: is not a readable .xlsx workbook ({exc})") from None


def _defused(shown, zf, member):
    import defusedxml
    from defusedxml.ElementTree import ParseError, fromstring

    try:
        data = zf.read(member)  # bounded: zipfile stops at the declared size, checks the CRC
        if data.strip():
            fromstring(data, forbid_dtd=True)
    except defusedxml.DefusedXmlException as exc:
        raise _declares(shown, member.filename, exc) from None
    except ParseError as exc:
        raise WorkbookError(f"{shown}: member {member.filename} is not well-formed XML "
                            f"({exc})") from None
    except _READ_ERRORS as exc:
        raise WorkbookError(f"{shown}: is not a readable .xlsx workbook ({exc})") from None


def first_sheet_member(path, zf):
    """The zip member of the workbook's first worksheet, from workbook.xml and its rels."""
    return sheet_member(path, zf)


def sheet_member(path, zf, title=None):
    """The zip member of the worksheet named ``title`` (the first one for None), from
    workbook.xml and its rels; None for a title the workbook does not have."""
    from defusedxml.ElementTree import fromstring

    shown = display(path)
    try:
        book = fromstring(zf.read("xl/workbook.xml"), forbid_dtd=True)
        rels = fromstring(zf.read("xl/_rels/workbook.xml.rels"), forbid_dtd=True)
    except Exception:  # noqa: BLE001 - checked by open_zip; anything left is a broken package
        raise WorkbookError(f"{shown}: has no readable workbook.xml, expected an .xlsx "
                            "workbook") from None
    sheets = [e for e in book.iter() if e.tag.endswith("}sheet")]
    if title is not None:
        sheets = [e for e in sheets if e.get("name") == title]
        if not sheets:
            return None
    sheet = sheets[0] if sheets else None
    rid = None if sheet is None else next(
        (v for k, v in sheet.attrib.items() if k.endswith("}id")), None)
    target = next((e.get("Target") for e in rels if e.get("Id") == rid), None)
    if not target:
        raise WorkbookError(f"{shown}: names no worksheet, expected the report's parameter "
                            "sheet")
    name = target.lstrip("/") if target.startswith("/") else posixpath.normpath(
        posixpath.join("xl", target))
    if name not in zf.namelist():
        raise WorkbookError(f"{shown}: its first sheet {target} is missing from the package")
    return name


def _column_number(letters):
    n = 0
    for ch in letters:
        n = n * 26 + ord(ch) - 64
    return n


class _PastCap(Exception):
    """The extent scanned so far already holds more cells than the cap."""


def _extent_parser(cap):
    """A defusedxml SAX parser (no DTD, no entities) whose expat start-tag handler only notes
    ``<row r>`` and the widest ``<c r>``; text and end tags are not reported at all. It stops
    with :class:`_PastCap` once the extent passes ``cap`` cells."""
    from defusedxml.expatreader import DefusedExpatParser

    class ExtentParser(DefusedExpatParser):
        def reset(self):
            super().reset()  # installs defusedxml's DTD and entity handlers
            self.rows, self.widest, self.run, self.widest_run = 0, (0, ""), 0, 0
            self.columns = 1
            self._parser.StartElementHandler = self._start
            self._parser.EndElementHandler = None
            self._parser.CharacterDataHandler = None

        def _start(self, name, attrs, _digits="0123456789"):
            if name == "c" or name.endswith(":c"):
                ref = attrs.get("r")
                if ref:  # compare columns as (length, letters): no decoding per cell
                    letters = ref.rstrip(_digits).upper()
                    key = (len(letters), letters)
                    if key > self.widest:
                        self.widest = key
                        self.columns = _column_number(letters) + self.widest_run
                    self.run = 0
                else:  # an implicit position: the previous one plus 1
                    self.run += 1
                    if self.run > self.widest_run:
                        self.widest_run = self.run
                        self.columns = _column_number(self.widest[1]) + self.widest_run
            elif name == "row" or name.endswith(":row"):
                ref = attrs.get("r")
                self.rows = int(ref) if ref and ref.isdigit() else self.rows + 1
                self.run = 0
            else:
                return
            if cap is not None and self.rows * self.columns > cap:
                raise _PastCap

    return ExtentParser(forbid_dtd=True)


def sheet_extent(path, zf, member, cap=None, what="its first sheet"):
    """``(rows, columns)`` spanned by the cells a worksheet really holds, from A1.

    Not the ``<dimension>`` tag, which may lie: one defusedxml pass over the ``<row>`` and
    ``<c>`` start tags (~0.5 M cells a second). Cells without an ``r`` attribute count on
    from the last explicit one, so ``columns`` is an upper bound. With ``cap``, the scan stops
    with a :class:`WorkbookError` as soon as the extent passes ``cap`` cells.

    Raises
    ------
    WorkbookError
        For XML that is not well-formed or declares a DTD or entities, or past ``cap``.
    """
    import xml.sax

    import defusedxml

    parser = _extent_parser(cap)
    try:
        with zf.open(member) as fh:
            parser.parse(fh)
    except _PastCap:
        raise WorkbookError(f"{display(path)}: {what} spans at least {parser.rows:,} "
                            f"rows x {parser.columns:,} columns, expected at most {cap:,} "
                            "cells") from None
    except defusedxml.DefusedXmlException as exc:
        raise _declares(display(path), member, exc) from None
    except (xml.sax.SAXException, *_READ_ERRORS) as exc:
        raise WorkbookError(f"{display(path)}: {member} is not a readable worksheet "
                            f"({exc})") from None
    return parser.rows, _column_number(parser.widest[1]) + parser.widest_run


# -- .xls (BIFF in an OLE compound file) -------------------------------------------------------
#: BIFF5/8 cell records: type -> whether the record spans columns (MULRK, MULBLANK).
_CELL_RECORDS = {0x0203: False, 0x027E: False, 0x00FD: False, 0x0204: False, 0x0006: False,
                 0x0201: False, 0x0205: False, 0x00D6: False, 0x00BD: True, 0x00BE: True}
_BOF, _EOF = 0x0809, 0x000A


def xls_extents(path, data):
    """``[(rows, columns)]`` spanned by the cell records of each sheet of an .xls, in order.

    Scans the BIFF records of the Workbook stream (olefile opens the compound file); each
    sheet is the substream between a BOF and its EOF after the workbook globals.

    Raises
    ------
    WorkbookError
    """
    import olefile

    shown = display(path)
    try:
        ole = olefile.OleFileIO(io.BytesIO(data))
        name = next((n for n in ("Workbook", "Book") if ole.exists(n)), None)
        if name is None:
            raise WorkbookError(f"{shown}: holds no Workbook stream, {EXPECTED}")
        if ole.get_size(name) > limits.MAX_INPUT_BYTES:
            raise WorkbookError(f"{shown}: its Workbook stream is larger than the file cap")
        stream = ole.openstream(name).read()
    except WorkbookError:
        raise
    except Exception as exc:  # noqa: BLE001 - olefile raises its own types for broken files
        raise WorkbookError(f"{shown}: is not a readable .xls workbook ({exc})") from None
    extents, depth, index, current = [], 0, -1, None
    pos, end = 0, len(stream)
    while pos + 4 <= end:
        rtype, size = struct.unpack_from("<HH", stream, pos)
        body, pos = pos + 4, pos + 4 + size
        if rtype == _BOF:
            depth += 1
            if depth == 1:  # substream 0 is the workbook globals, then one per sheet
                index += 1
                current = [0, 0] if index > 0 else None
        elif rtype == _EOF:
            if depth == 1 and current is not None:
                extents.append(tuple(current))
                current = None
            depth = max(depth - 1, 0)
        elif depth == 1 and current is not None and rtype in _CELL_RECORDS and (
                size >= 4 and pos <= end):
            row, col = struct.unpack_from("<HH", stream, body)
            last = col
            if _CELL_RECORDS[rtype] and size >= 6:  # MULRK, MULBLANK: last column at the end
                last = struct.unpack_from("<H", stream, pos - 2)[0]
            current[0] = max(current[0], row + 1)
            current[1] = max(current[1], col + 1, last + 1)
    if current is not None:
        extents.append(tuple(current))  # a sheet cut short: still count it
    return extents


def check_extent(path, what, rows, columns, cap):
    """Refuse a sheet whose extent holds more than ``cap`` cells."""
    if rows * columns > cap:
        raise WorkbookError(f"{display(path)}: {what} spans {rows:,} rows x {columns:,} columns, "
                            f"expected at most {cap:,} cells")
