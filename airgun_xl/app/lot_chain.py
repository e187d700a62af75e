"""A lot's chain of proposals as the archive holds it (``history --lot``, the laws page), and
what the whole archive's chains say of the model's own error (issue 60): read by ``next``
and ``design`` alike, so that neither imports the other."""
from __future__ import annotations

import math
from collections import Counter
from pathlib import Path
from typing import Any, TypeGuard

from ..cells import address
from ..errors import ArchiveError, OptionError

#: How a proposal states each judged figure: its unit and the factor from the judge's (kG, s,
#: m/s), and the digits shown.
FIGURE_UNITS = {"peak": ("kG", 1.0, 3), "duration": ("ms", 1e3, 3),
                "velocity change": ("m/s", 1.0, 2)}


def expected_text(expected: Any) -> str:
    """``peak 9.102 kG (8.805 to 9.447), duration ...``: a record's expected figures, each
    with its 90 % range ('' when the record holds none)."""
    parts = []
    for name, (unit, factor, digits) in FIGURE_UNITS.items():
        values = expected.get(name) if isinstance(expected, dict) else None
        if not (isinstance(values, list) and len(values) == 3
                and all(isinstance(v, (int, float)) for v in values)):
            continue
        lo, mid, hi = (float(v) * factor for v in values)
        parts.append(f"{name} {mid:.{digits}f} {unit} ({lo:.{digits}f} to {hi:.{digits}f})")
    return ", ".join(parts)


def measured_text(measured: Any) -> str:
    """``peak 9.214 kG, duration 4.602 ms``: a record's measured figures, each in the unit its
    verdict gave ('' when none)."""
    parts = []
    for name in FIGURE_UNITS:
        found = measured.get(name) if isinstance(measured, dict) else None
        if not isinstance(found, dict):
            continue
        value = found.get("value")
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            parts.append(f"{name} {float(value):.5g} {str(found.get('unit', ''))[:8]}")
    return ", ".join(parts)


def knobs_text(row: dict[str, Any]) -> str:
    """``A28 241.5, E13 0.0381; expected peak ...``: a chain row's next setting, every knob it
    sets and what it expects there ('' when the row holds no knob)."""
    knobs = {k: v for k, v in (row.get("next_knobs") or {}).items()
             if isinstance(v, (int, float)) and not isinstance(v, bool)}
    if not knobs:
        return ""
    expected = expected_text(row.get("next_expected"))
    return (", ".join(f"{k} {v:.6g}" for k, v in knobs.items())
            + (f"; expected {expected}" if expected else ""))


def said_once(warnings: list[list[str]]) -> list[tuple[list[str], int]]:
    """A chain's warnings, proposal by proposal, each said once: at the first proposal that
    carries it, with how many of the chain's proposals carry it when more than one ("... (on 4
    of the lot's 6 proposals)"); ``[(said first here, how many said above are carried
    again)]``, a row a proposal."""
    carried = [list(dict.fromkeys(ws)) for ws in warnings]
    counts = Counter(w for ws in carried for w in ws)
    seen: set[str] = set()
    out = []
    for ws in carried:
        new = [w for w in ws if w not in seen]
        seen.update(new)
        out.append(([w if counts[w] == 1 else
                     f"{w} (on {counts[w]} of the lot's {len(carried)} proposals)" for w in new],
                    len(ws) - len(new)))
    return out


def chain(root: str | Path | None, lot: str) -> list[dict[str, Any]]:
    """``history --lot``: a row a proposal (the shot fired, its verdict, the P(PASS) predicted
    for it before it was fired when it was fired from a proposal's workbook, the law version
    made, the next setting and its P(PASS))."""
    from ..archive import Archive, archive_dir
    from ..archive.lots import proposals

    found = Archive(archive_dir(root))
    rows: list[dict[str, Any]] = []
    predicted: dict[str, Any] = {}
    chained = proposals(found.root, lot)
    if not chained:
        raise OptionError(f"--lot: found {lot!r}, which has no chain in {found.root}, "
                          "expected a lot airgun-xl next has kept there")
    for version, record in chained:
        shots = record.get("shots") or []
        fired = shots[-1].get("shot_sha256") if shots else None
        before = predicted.get(fired) if isinstance(fired, str) else None
        knobs = {address("v31"): record.get("setting_A28")}
        if isinstance(record.get("second_cell"), str):
            knobs[record["second_cell"][:8]] = record.get("second_value")
        rows.append({"proposal": f"{lot}@{version}", "shot": record.get("shot"),
                     "verdict": record.get("verdict"),
                     "predicted_before": before[0] if before else None,
                     "expected_before": before[1] if before else None,
                     "model_before": before[2] if before else None,
                     "measured": record.get("measured"), "law": record.get("law"),
                     "against_report": record.get("against_report"),
                     "next_A28": record.get("setting_A28"), "next_knobs": knobs,
                     "next_p_pass": record.get("p_pass"),
                     "next_expected": record.get("expected"),
                     "created": record.get("created", "")})
        if isinstance(record.get("next_sha256"), str):
            predicted[record["next_sha256"]] = (record.get("p_pass"), record.get("expected"),
                                                record.get("expected_model"))
    return rows


def archive_pairs(root: str | Path) -> list[dict[str, tuple[float, ...]]]:
    """Every pair of expected and measured judged figures the archive at ``root`` holds
    across its lots: a shot fired from a proposal's workbook, what that proposal expected of
    it and what its verdict measured, ``{figure: (expected, measured, explained)}`` in the
    judge's units (kG, s, m/s). ``expected`` is the median of the model's own draws before its
    error was drawn and ``explained`` the standard deviation of their log that the drawn
    inputs give (from their 90 % range, as a normal's: (log 95th - log 5th) / 3.29), so that
    the model's error is what the inputs do not explain; a record older than that keeps the
    median with the error drawn and no ``explained`` (a pair of two). What the archive gives
    is read as untrusted: a value that is no finite number is left out, a unit not known
    refused."""
    from ..archive.lots import lot_names
    from ..units import SHOWN_UNITS

    pairs = []
    for lot in lot_names(root):
        for row in chain(root, lot):
            expected, measured = row.get("expected_before"), row.get("measured")
            model = row.get("model_before")
            if not isinstance(expected, dict) or not isinstance(measured, dict):
                continue
            pair: dict[str, tuple[float, ...]] = {}
            for name in FIGURE_UNITS:
                values, found = expected.get(name), measured.get(name)
                if not (isinstance(values, list) and len(values) == 3
                        and isinstance(found, dict)):
                    continue
                mid, value, unit = values[1], found.get("value"), found.get("unit")
                if not (_number(mid) and _number(value)):
                    continue
                table = SHOWN_UNITS.get(name, {"m/s": ("m/s", 1.0)})
                if unit not in table:
                    raise ArchiveError(f"{row['proposal']}: the measured {name}'s unit "
                                       f"{str(unit)[:20]!r}, expected one of "
                                       f"{', '.join(sorted(table))}")
                own = _model_range(model.get(name) if isinstance(model, dict) else None)
                if own is None:
                    pair[name] = (float(mid), float(value) / table[unit][1])
                else:
                    pair[name] = (own[0], float(value) / table[unit][1], own[1])
            if pair:
                pairs.append(pair)
    return pairs


def _model_range(values: Any) -> tuple[float, float] | None:
    """(median, standard deviation of the log) of a proposal's model figures ``[5th, 50th,
    95th]``, or None where they are not three positive, ordered finite numbers."""
    from ..studies.model_error import explained_spread

    if not (isinstance(values, list) and len(values) == 3 and all(map(_number, values))):
        return None
    lo, mid, hi = (float(v) for v in values)
    if not 0 < lo <= mid <= hi:
        return None
    return mid, explained_spread(lo, hi)


def _number(value: Any) -> TypeGuard[float]:
    """A finite number (no bool), as a record read from the archive must give it."""
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value))


def model_error_of(root: str | Path | None) -> Any:
    """The model's error (:class:`~airgun_xl.studies.model_error.ModelError`) from the
    archive at ``root``'s pairs (:func:`archive_pairs`), the prior without an archive."""
    from ..studies.model_error import ModelError

    if root is None or not Path(root).is_dir():
        return ModelError.prior()
    return ModelError.from_pairs(archive_pairs(root), f"{root}: the archive's pairs")
