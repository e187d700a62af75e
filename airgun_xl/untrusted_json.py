"""One bounded, typed reader for every JSON file the tool reads (issue 32): tolerance profiles
and the archive's records (crush laws, verdicts, an entry's summary, parameters, provenance
and manifest). A record may have been edited by hand, broken by a disk, or planted, so each is
read as untrusted input:

- only a regular file is read (a FIFO would block, a device never end), its size capped by
  :data:`MAX_BYTES` before a byte is parsed, and read to that cap only (a sparse 3 GB file is
  refused by its size);
- its nesting is capped at :data:`MAX_DEPTH` (checked on the text, before the parser's own
  recursion), its integers at :data:`MAX_INT_DIGITS` digits, and ``NaN``/``Infinity`` and
  numbers past a float are refused;
- it is validated against its declared schema (:data:`SCHEMAS`, JSON Schema, checked by the
  ``jsonschema`` library), so a field of the wrong type is refused naming the file and the
  field, never met as a ``TypeError`` later.

Every refusal is one line: ``FILE: FIELD: found ..., expected ...``.
"""
from __future__ import annotations

import json
import math
import os
import stat
from pathlib import Path
from typing import Any

from .errors import AirgunXlError

#: The largest file read, by kind [bytes]: each is a few kilobytes when the tool writes it.
MAX_BYTES = {"profile": 65_536, "law": 1 << 20, "verdict": 1 << 20, "summary": 4 << 20,
             "params": 1 << 20, "provenance": 1 << 20, "manifest": 1 << 20, "marker": 4096,
             "proposal": 4 << 20}

#: The deepest nesting of arrays and objects read (the tool writes 4 at most).
MAX_DEPTH = 32

#: The longest integer read, in digits (past a double's exact integers).
MAX_INT_DIGITS = 18

_NUMBER = {"type": "number"}
_TEXT = {"type": "string"}
_TEXTS = {"type": "array", "items": _TEXT}
_NUMBER_OR_NULL = {"type": ["number", "null"]}
_CRITERION = {
    "type": "object", "required": ["name", "value", "unit", "margin", "margin_unit", "passed"],
    "properties": {"name": _TEXT, "value": _NUMBER_OR_NULL, "unit": _TEXT,
                   "low": _NUMBER_OR_NULL, "high": _NUMBER_OR_NULL,
                   "margin": _NUMBER_OR_NULL, "margin_unit": _TEXT,
                   "passed": {"type": "boolean"}, "detail": _TEXT,
                   "judged": {"type": "boolean"}, "uncertainty": _NUMBER_OR_NULL},
    "description": "a criterion: name, value, unit, margin, margin_unit and passed"}

#: The schema of each kind of record, as the tool writes it.
SCHEMAS: dict[str, dict] = {
    "profile": {
        "type": "object", "description": "an object of specification fields",
        "properties": {"notes": {"anyOf": [_TEXT, _TEXTS], "description": "text or a list "
                                                                           "of text"}},
        "additionalProperties": {"type": ["string", "number"],
                                 "description": "text, or a number in the field's unit"}},
    "law": {
        "type": "object", "required": ["coefficients", "v_range"],
        "description": "a crush law record",
        "properties": {
            "name": _TEXT,
            "coefficients": {"type": "array", "items": _NUMBER, "minItems": 7, "maxItems": 7,
                             "description": "7 numbers"},
            "v_range": {"type": "array", "items": _NUMBER, "minItems": 2, "maxItems": 2,
                        "description": "2 numbers [m/s], the lower first"},
            "shots": {"type": "array", "items": {"type": "object"}},
            "scores": {"type": "array", "items": {"type": "object"}},
            "intervals": {"type": "array", "items": {"type": "object"},
                          "description": "the law at its nodes with their intervals"},
            "created": _TEXT, "command": _TEXTS}},
    "verdict": {
        "type": "object", "required": ["shot", "verdict", "criteria"],
        "description": "a verdict record",
        "properties": {"shot": _TEXT, "shot_sha256": {"type": ["string", "null"]},
                       "verdict": {"enum": ["PASS", "FAIL", "NOT JUDGED"]},
                       "criteria": {"type": "array", "items": _CRITERION},
                       "tolerances": _TEXTS, "definitions": _TEXTS, "specification": _TEXT,
                       "notes": _TEXTS, "warnings": _TEXTS, "recording": _TEXT,
                       "recording_sha256": {"type": ["string", "null"]}, "report": _TEXT,
                       "recording_read": {"type": ["object", "null"],
                                          "additionalProperties": _TEXT,
                                          "description": "what the recording said of "
                                                         "itself, text by label"},
                       "created": _TEXT, "command": _TEXTS, "lot": _TEXT,
                       "test": {"type": "object", "additionalProperties": _TEXT,
                                "description": "the test's identification, text by field"},
                       "trace": {"type": ["object", "null"],
                                 "description": "the record judged, thinned for a drawing",
                                 "properties": {"time_ms": {"type": "array"},
                                                "kg": {"type": "array"},
                                                "upper_kg": {"type": ["array", "null"]},
                                                "lower_kg": {"type": ["array", "null"]},
                                                "onset_ms": _NUMBER_OR_NULL,
                                                "samples": {"type": "integer"},
                                                "thinned": _TEXT}}}},
    "proposal": {
        "type": "object", "description": "a lot's proposal (next)",
        "required": ["lot", "shot", "verdict", "law", "setting_A28", "p_pass", "interval",
                     "shots", "next_sha256"],
        "properties": {
            "lot": _TEXT, "shot": _TEXT, "recording": _TEXT,
            "verdict": {"enum": ["PASS", "FAIL", "NOT JUDGED"]}, "law": _TEXT, "scale": _NUMBER,
            "scale_error": _NUMBER_OR_NULL, "setting_A28": _NUMBER,
            "second_cell": _TEXT, "second_value": _NUMBER, "tilt": _NUMBER,
            "tilt_error": _NUMBER_OR_NULL, "tilt_about": _NUMBER,
            "whole": {"type": "boolean"}, "shape_chi2": _NUMBER_OR_NULL,
            "shape_dof": {"type": "integer"}, "shape_p": _NUMBER_OR_NULL,
            "whole_nodes": {"type": "array", "items": {"type": "object"},
                            "description": "the law fitted whole at its nodes, with their "
                                           "intervals"},
            "p_pass": {"type": "number", "minimum": 0, "maximum": 1},
            "interval": {"type": "array", "items": _NUMBER, "minItems": 2, "maxItems": 2},
            "draws": {"type": "integer"}, "most_likely_to_fail": {"type": ["string", "null"]},
            "confidence": _NUMBER, "reached": {"type": "boolean"}, "sd": _TEXTS,
            "gun": _TEXT, "model_error": _TEXT, "gun_name": _TEXT, "step": _TEXTS,
            "unrounded": {"type": "object", "required": ["A28_m_s", "p_pass"],
                          "properties": {"A28_m_s": _NUMBER,
                                         "p_pass": {"type": "number", "minimum": 0,
                                                    "maximum": 1}},
                          "description": "the best found between the knobs' steps"},
            "launch": {"type": "array", "items": {
                "type": "object",
                "required": ["shot_sha256", "recording_sha256", "speed_m_s", "factor",
                             "error"],
                "properties": {"shot_sha256": {"type": "string", "pattern": "^[0-9a-f]{64}$"},
                               "recording_sha256": {"type": "string",
                                                    "pattern": "^[0-9a-f]{64}$"},
                               "speed_m_s": {"type": "number", "exclusiveMinimum": 0},
                               "factor": {"type": "number", "exclusiveMinimum": 0},
                               "error": {"type": ["number", "null"], "minimum": 0}}},
                "description": "each shot's launch velocity fitted: a factor on its set "
                               "value, with its standard error"},
            "seed": {"type": "integer"}, "next_workbook": _TEXT,
            "next_sha256": {"type": "string", "pattern": "^[0-9a-f]{64}$"},
            "shots": {"type": "array", "items": {
                "type": "object",
                "required": ["shot", "shot_sha256", "recording", "recording_sha256"],
                "properties": {"shot": _TEXT, "recording": _TEXT,
                               "shot_sha256": {"type": "string", "pattern": "^[0-9a-f]{64}$"},
                               "recording_sha256": {"type": "string",
                                                    "pattern": "^[0-9a-f]{64}$"},
                               "sign": {"enum": [1, -1, 1.0, -1.0]},
                               "time_unit": {"type": ["string", "null"]},
                               "accel_unit": {"type": ["string", "null"]},
                               "channel": {"type": ["string", "null"]},
                               "event": {"type": ["integer", "null"], "minimum": 1},
                               "at": {"type": ["number", "null"]}}},
                "description": "the lot's shots: each workbook and recording, with hashes"},
            "warnings": _TEXTS, "created": _TEXT, "command": _TEXTS}},
    "summary": {
        "type": "object", "description": "an entry's figures",
        "properties": {
            "warnings": _TEXTS,
            "dominant_frequencies_hz": {"type": "array", "items": _NUMBER},
            "predicted_verdict": {
                "type": "object", "required": ["verdict", "criteria"],
                "properties": {"verdict": {"enum": ["PASS", "FAIL", "NOT JUDGED"]},
                               "specification": _TEXT,
                               "criteria": {"type": "array", "items": _CRITERION},
                               "tolerances": _TEXTS, "definitions": _TEXTS}}},
        "additionalProperties": {"type": ["number", "null", "array"],
                                 "description": "a number, null or a list of numbers"}},
    "params": {
        "type": "array", "description": "the cells the run read",
        "items": {"type": "object", "required": ["cell", "label", "value", "unit"],
                  "properties": {"cell": _TEXT, "label": _TEXT, "unit": _TEXT,
                                 "meaning": _TEXT,
                                 "value": {"type": ["number", "string", "null"]}}}},
    "provenance": {
        "type": "object", "description": "the run's provenance",
        "required": ["engine", "integrator", "model", "started", "run_seconds", "command"],
        "properties": {"engine": _TEXT, "integrator": _TEXT, "model": _TEXT,
                       "started": _TEXT, "run_seconds": _NUMBER, "command": _TEXTS,
                       "input": {"type": ["string", "null"]},
                       "input_sha256": {"type": ["string", "null"]},
                       "crush_law": {"type": ["object", "null"]}}},
    "manifest": {
        "type": "object", "required": ["index", "files"], "description": "an entry's manifest",
        "properties": {"index": {"type": "object", "required": ["shot", "version"],
                                 "properties": {"shot": _TEXT, "version": {"type": "integer"}}},
                       "files": {"type": "object", "additionalProperties": _TEXT}}},
    "marker": {
        "type": "object", "required": ["format"], "description": "an archive's marker",
        "properties": {"format": {"type": "integer", "enum": [1]}, "tool": _TEXT,
                       "index": {"enum": ["sqlite", "server"]},
                       "identity": {"type": "string", "pattern": "^[0-9a-f]{32}$"}}},
}


def _depth(text: str) -> int:
    """The deepest nesting of the text's arrays and objects (strings skipped)."""
    depth = deepest = 0
    in_string = escaped = False
    for ch in text:
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
            if deepest > MAX_DEPTH:
                return deepest
        elif ch in "]}":
            depth -= 1
    return deepest


class _Refused(ValueError):
    """A JSON value past the reader's bounds (its words say which)."""


def _integer(text: str) -> int:
    if len(text.lstrip("-")) > MAX_INT_DIGITS:
        raise _Refused(f"an integer of {len(text.lstrip('-')):,} digits (at most "
                       f"{MAX_INT_DIGITS})")
    return int(text)


def _float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise _Refused(f"the number {text[:20]} past a float")
    return value


def _constant(name: str) -> None:
    raise _Refused(f"{name}, which is not JSON")


def _object(pairs: list[tuple[str, Any]]) -> dict:
    """An object, refusing a key given twice: the last would win unseen (a profile's
    ``"peak_tolerance": 10, "peak_tolerance": 50`` judged with 50)."""
    out: dict = {}
    for key, value in pairs:
        if key in out:
            raise _Refused(f"the key {short(key)} twice (at its last: {short(value, 30)})")
        out[key] = value
    return out


def short(value: Any, limit: int = 60) -> str:
    """A value as a message quotes it: its repr, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit - 15]}... ({len(text):,} characters)"


def read_json(path: Path | str, kind: str, shown: str,
              error: type[AirgunXlError] = AirgunXlError) -> Any:
    """The JSON of ``path``, a record of ``kind`` (:data:`SCHEMAS`), read within the bounds
    above; ``shown`` names it in messages.

    Raises
    ------
    error
        One line naming ``shown`` (and the field at fault) for a missing, special, oversized,
        deep or malformed file, or one its schema refuses.
    """
    path = Path(path)
    cap = MAX_BYTES[kind]
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise error(f"{shown}: no such file, expected a JSON {kind} record") from None
    except (OSError, ValueError) as exc:
        raise error(f"{shown}: cannot be read ({getattr(exc, 'strerror', None) or exc})"
                    ) from None
    if not stat.S_ISREG(info.st_mode):
        raise error(f"{shown}: is not a regular file (a FIFO, a device or a folder), expected "
                    f"a JSON {kind} record")
    if info.st_size > cap:
        raise error(f"{shown}: found {info.st_size:,} bytes, expected a {kind} record of at "
                    f"most {cap:,}")
    try:
        with open(path, "rb") as fh:
            raw = fh.read(cap + 1)
    except OSError as exc:
        raise error(f"{shown}: cannot be read ({exc.strerror or exc})") from None
    if len(raw) > cap:
        raise error(f"{shown}: found over {cap:,} bytes, expected a {kind} record of at most "
                    f"{cap:,}")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise error(f"{shown}: is not UTF-8 text, expected a JSON {kind} record") from None
    if _depth(text) > MAX_DEPTH:
        raise error(f"{shown}: found arrays or objects nested over {MAX_DEPTH} deep, expected "
                    f"a JSON {kind} record")
    try:
        data = json.loads(text, parse_int=_integer, parse_float=_float,
                          parse_constant=_constant, object_pairs_hook=_object)
    except _Refused as exc:
        raise error(f"{shown}: found {exc}, expected a JSON {kind} record") from None
    except (ValueError, RecursionError) as exc:
        raise error(f"{shown}: is not valid JSON ({type(exc).__name__}: "
                    f"{str(exc).splitlines()[0][:80]}), expected a {kind} record") from None
    QUICK_CHECKS.get(kind, check)(data, kind, shown, error)
    return data


def check_marker(data: Any, kind: str, shown: str,
                 error: type[AirgunXlError] = AirgunXlError) -> None:
    """The marker's schema, checked without importing jsonschema (50 ms, paid by every command
    that opens an archive). It accepts and refuses exactly what :func:`check` does with
    ``SCHEMAS["marker"]``: tests/test_server_archive.py compares the two on random input."""
    import re

    def refuse(field: str, found: Any, expected: str) -> None:
        raise error(f"{shown}: {field}: found {short(found)}, expected {expected}")

    if not isinstance(data, dict):
        refuse("the record", data, "an archive's marker")
    if "format" not in data:
        refuse("the record", data, "'format', a required field")
    found = data["format"]  # JSON Schema's integer 1: 1 or 1.0, never true
    if isinstance(found, bool) or not isinstance(found, (int, float)) or found != 1:
        refuse("format", found, "1")
    if "tool" in data and not isinstance(data["tool"], str):
        refuse("tool", data["tool"], "text")
    if "index" in data and data["index"] not in ("sqlite", "server"):
        refuse("index", data["index"], "sqlite or server")
    if "identity" in data and not (isinstance(data["identity"], str)
                                   and re.search(SCHEMAS["marker"]["properties"]["identity"][
                                       "pattern"], data["identity"])):
        refuse("identity", data["identity"], "the archive's identity, 32 hexadecimal digits")


#: Kinds checked by a short check of their own (import time), instead of :func:`check`.
QUICK_CHECKS = {"marker": check_marker}


def check(data: Any, kind: str, shown: str, error: type[AirgunXlError] = AirgunXlError) -> None:
    """Validate ``data`` against the schema of ``kind``; refuse the first error in one line
    naming ``shown`` and the field."""
    from jsonschema import Draft202012Validator
    from jsonschema.exceptions import best_match

    found = best_match(Draft202012Validator(SCHEMAS[kind]).iter_errors(data))
    if found is None:
        return
    field = "/".join(str(p) for p in found.absolute_path) or "the record"
    expected = found.schema.get("description") if isinstance(found.schema, dict) else None
    if not expected or found.validator == "required":
        expected = _expected(found.validator, found.validator_value)
    raise error(f"{shown}: {field}: found {short(found.instance)}, expected {expected}")


def _expected(validator: Any, value: Any) -> str:
    """A schema keyword's demand in words."""
    if validator == "type":
        kinds = [str(k) for k in (value if isinstance(value, list) else [value])]
        words = {"number": "a number", "string": "text", "array": "a list",
                 "object": "an object", "null": "null", "boolean": "true or false",
                 "integer": "a whole number"}
        return " or ".join(words.get(k, k) for k in kinds)
    if validator == "required":
        return f"the fields {', '.join(value)}"
    if validator == "enum":
        return f"one of {', '.join(map(str, value))}"
    if validator in ("minItems", "maxItems"):
        return f"{'at least' if validator == 'minItems' else 'at most'} {value} items"
    return f"{validator} {short(value, 40)}"


def printable(text: object) -> str:
    """``text`` with its control characters (an escape sequence stored in a record) shown
    as escapes, not sent to the terminal."""
    return "".join(ch if ch.isprintable() else ascii(ch)[1:-1] for ch in str(text))
