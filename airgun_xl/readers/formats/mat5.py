"""MATLAB's level 5 MAT-file (v5, v6 and v7, compressed or not), read by its published layout:
the variables' headers, and a named numeric or text variable's values.

scipy.io reads these files, but not safely: a damaged file makes its compiled reader
(``VarReader5.read_numeric``) read past its buffer and crash the process (a segmentation
fault in tests/test_recording_formats.py's damaged files, scipy 1.17.1), which no ``except``
can turn into one line. This reader walks the elements with every byte count checked against
the bytes there are, inflates a compressed variable with a cap on its output, and never
recurses (a cell, a structure or an object is listed by its class and skipped whole).
tests/test_recording_formats.py checks it against scipy.io on files scipy writes.

Layout (MathWorks, "MAT-File Format", level 5): a 128-byte header whose bytes 126-127 are
``IM`` (little-endian) or ``MI``; then data elements, each an 8-byte tag (type, byte count)
and its data padded to 8 bytes, or a 4-byte small tag with up to 4 bytes of data. A variable
is an ``miMATRIX`` element (or an ``miCOMPRESSED`` one holding it, zlib): array flags (the
class), dimensions, name, real part, imaginary part if complex.
"""
from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np

#: Data types: miINT8 ... miUTF32 -> numpy kind.
MI_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 9: "f8",
            12: "i8", 13: "u8", 16: "u1", 17: "u2", 18: "u4"}
MI_MATRIX, MI_COMPRESSED = 14, 15

#: Array classes: mx*_CLASS -> MATLAB's name of it.
CLASSES = {1: "cell", 2: "struct", 3: "object", 4: "char", 5: "sparse", 6: "double",
           7: "single", 8: "int8", 9: "uint8", 10: "int16", 11: "uint16", 12: "int32",
           13: "uint32", 14: "int64", 15: "uint64", 16: "function", 17: "opaque"}

#: Bytes a variable's header takes at most once inflated (flags, dims up to 32, a name of 64).
HEADER_BYTES = 8 + 16 + 8 + 32 * 4 + 8 + 64 + 8


class MatError(ValueError):
    """The bytes are not what the layout says they must be; the text says where."""


@dataclass(frozen=True)
class Variable:
    """A variable's header: its ``shape``, its ``kind`` (MATLAB's class name), whether it is
    ``complex``, and where its element is (``start``, ``size`` in the file, ``compressed``)."""

    name: str
    shape: tuple[int, ...]
    kind: str
    complex: bool
    start: int
    size: int
    compressed: bool


class Mat5:
    """The variables of a level 5 MAT-file's ``data`` (bytes)."""

    def __init__(self, data: bytes, max_values: int) -> None:
        if len(data) < 128:
            raise MatError(f"{len(data)} bytes, shorter than the 128-byte header")
        marker = data[126:128]
        if marker not in (b"IM", b"MI"):
            raise MatError(f"endian marker {marker!r} at byte 126, expected 'IM' or 'MI'")
        self.order = "<" if marker == b"IM" else ">"
        self.data = data
        self.max_values = max_values
        self.variables: dict[str, Variable] = {}
        at = 128
        while at + 8 <= len(data):
            kind, size = self._tag_words(data, at)
            end = at + 8 + size
            if end > len(data):
                raise MatError(f"the element at byte {at} declares {size:,} bytes, past the "
                               f"file's end ({len(data):,} bytes)")
            if kind == MI_COMPRESSED:
                head = _inflate(data[at + 8:end], HEADER_BYTES, at)
                variable = self._header(head, at, size, compressed=True)
            elif kind == MI_MATRIX:
                variable = self._header(data[at + 8:end], at, size, compressed=False)
            else:
                raise MatError(f"the element at byte {at} is of type {kind}, expected a "
                               "variable (miMATRIX or miCOMPRESSED)")
            if variable is not None and variable.name not in self.variables:
                self.variables[variable.name] = variable  # the first of a repeated name
            at = end if kind == MI_COMPRESSED else at + 8 + _padded(size)

    def _tag_words(self, data: bytes, at: int) -> tuple[int, int]:
        kind, size = np.frombuffer(data, f"{self.order}u4", 2, at).tolist()
        return int(kind), int(size)

    def _element(self, data: bytes, at: int) -> tuple[int, bytes, int]:
        """(type, data, the next element's offset) of the element at ``at`` of ``data``."""
        if at + 8 > len(data):  # a small element takes 8 bytes too
            raise MatError(f"a sub-element at byte {at} runs past its variable's end")
        first = int(np.frombuffer(data, f"{self.order}u4", 1, at)[0])
        if first >> 16:  # small data element: type and size in one word, data in the next 4
            kind, size = first & 0xFFFF, first >> 16
            if size > 4:
                raise MatError(f"a small element at byte {at} declares {size} bytes, expected "
                               "at most 4")
            return kind, data[at + 4:at + 4 + size], at + 8
        kind, size = self._tag_words(data, at)
        if at + 8 + size > len(data):
            raise MatError(f"a sub-element at byte {at} declares {size:,} bytes, past its "
                           "variable's end")
        return kind, data[at + 8:at + 8 + size], at + 8 + _padded(size)

    def _header(self, body: bytes, start: int, size: int, compressed: bool) -> Variable | None:
        """The variable whose miMATRIX element is at the start of ``body`` (inflated)."""
        matrix = body
        kind = MI_MATRIX
        if compressed:  # the inflated head of it: its tag, then its first sub-elements
            if len(body) < 8:
                raise MatError(f"the compressed element at byte {start} inflates to "
                               f"{len(body)} bytes, expected a variable")
            kind, _ = self._tag_words(body, 0)
            matrix = body[8:]
        if kind != MI_MATRIX:
            raise MatError(f"the compressed element at byte {start} holds type {kind}, "
                           "expected a variable (miMATRIX)")
        flags_type, flags, at = self._element(matrix, 0)
        if flags_type != 6 or len(flags) < 8:
            raise MatError(f"the variable at byte {start} has no array flags")
        word = int(np.frombuffer(flags, f"{self.order}u4", 1)[0])
        kind_code = word & 0xFF
        if kind_code not in CLASSES:
            raise MatError(f"the variable at byte {start} is of class {kind_code}, expected a "
                           "MATLAB class (1 to 17)")
        if CLASSES[kind_code] in ("function", "opaque", "object"):
            return None  # no dimensions follow in the same layout: listed as nothing
        dims_type, dims, at = self._element(matrix, at)
        if dims_type != 5 or not 2 <= len(dims) // 4 <= 32 or len(dims) % 4:
            raise MatError(f"the variable at byte {start} has no dimensions")
        shape = tuple(int(n) for n in np.frombuffer(dims, f"{self.order}i4"))
        if min(shape) < 0:
            raise MatError(f"the variable at byte {start} has dimensions {shape}")
        name_type, name, at = self._element(matrix, at)
        if name_type not in (1, 2, 16):
            raise MatError(f"the variable at byte {start} has no name")
        text = name.decode("latin-1")
        return Variable(text, shape, CLASSES[kind_code], bool(word & 0x0800), start, size,
                        compressed)

    def values(self, name: str) -> np.ndarray:
        """A numeric variable's real values (``complex`` ones give their real and imaginary
        parts as a complex array), or a text variable's as a 0-d array of str."""
        v = self.variables[name]
        count = math.prod(v.shape)
        if count > self.max_values:
            raise MatError(f"variable {name!r} declares {count:,} values, expected at most "
                           f"{self.max_values:,}")
        body = self.data[v.start + 8:v.start + 8 + v.size]
        if v.compressed:
            inflated = _inflate(body, count * 16 + 2 * HEADER_BYTES + 64, v.start)
            _, body, _ = self._element(inflated, 0)
        at = 0
        for _ in range(3):  # flags, dimensions, name
            _, _, at = self._element(body, at)
        parts = []
        for _ in range(2 if v.complex else 1):
            kind, raw, at = self._element(body, at)
            if kind not in MI_TYPES:
                raise MatError(f"variable {name!r} stores its values as type {kind}, expected "
                               "a numeric type")
            dtype = np.dtype(self.order + MI_TYPES[kind])
            if v.kind != "char" and len(raw) != count * dtype.itemsize:
                raise MatError(f"variable {name!r} declares {count:,} values and holds "
                               f"{len(raw) // dtype.itemsize:,}")
            if v.kind == "char":  # text: UTF-8 or UTF-16 as stored, else code points
                codec = {16: "utf-8", 17: "utf-16-le" if self.order == "<" else "utf-16-be"}
                text = raw.decode(codec[kind], "replace") if kind in codec else "".join(
                    chr(int(c)) for c in np.frombuffer(raw, dtype) if 0 < int(c) < 0x110000)
                return np.asarray(text)
            parts.append(np.frombuffer(raw, dtype))
        return parts[0] if len(parts) == 1 else parts[0] + 1j * parts[1]


def _padded(size: int) -> int:
    return size + (-size % 8)


def _inflate(body: bytes, cap: int, at: int) -> bytes:
    """At most ``cap`` bytes of a zlib stream (a bomb stops at the cap)."""
    try:
        return zlib.decompressobj().decompress(body, cap)
    except zlib.error as exc:
        raise MatError(f"the compressed element at byte {at} does not inflate ({exc})") from None
