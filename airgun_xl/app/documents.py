"""Outcomes as JSON documents (every command's ``--json``, for a LIMS): numbers in SI unless
a key names its unit, a value that is not finite as null, text in ASCII with control
characters escaped (a file's names never reach a terminal as codes)."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np


def plain(value: Any) -> Any:
    """``value`` as JSON's types: a dataclass as its fields, arrays and tuples as lists, a
    path as its text, NaN and infinities as None, anything else as its text."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, Path):
        return str(value)
    if value is None or isinstance(value, str):
        return value
    return str(value)


def dumps(document: dict[str, Any]) -> str:
    """One JSON document, indented, ASCII."""
    return json.dumps(plain(document), indent=1, allow_nan=False)
