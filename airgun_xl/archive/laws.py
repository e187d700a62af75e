"""The archive's library of crush laws: fitted laws kept by name, with their velocity range,
the shots they were fitted on and their scores, so that ``fill --crush-law NAME`` runs one.

Each law is a JSON file ``.laws/<name>/vNNNN.json`` of the archive folder (a hidden folder:
entry scans skip it). A name keeps every version: storing it again adds the next one, and
``NAME`` runs the latest, ``NAME@N`` version N. Versions are written by
:func:`airgun_xl.archive.records.store_record`, so two calibrations can store at once and none
is ever half-written.
"""
import datetime
import re
from pathlib import Path

from ..crush_law import DEGREE, CrushLaw
from ..errors import ArchiveError, OptionError
from ..transaction import display, signals_held
from ..untrusted_json import short
from .lots import committed
from .records import all_versions, read_record, versions
from .store import Archive, safe_name

LAWS = ".laws"
_REF = re.compile(r"^(?P<name>[^@]+?)(?:@(?P<version>\d{1,9}))?$")


def _folder(root, name):
    return Path(root) / LAWS / safe_name(name)


def store_law(root, name, law, shots, scores, command=(), intervals=None, proposal=None):
    """Keep ``law`` in the archive at ``root`` under ``name``; return its reference
    ``NAME@N``. With ``proposal`` (``next``'s), the law is the lot's only once the lot's
    proposal of that version names it (:func:`airgun_xl.archive.lots.committed`).

    Parameters
    ----------
    law : CrushLaw
    shots : list of dict
        Each shot the law was fitted on (its workbook, recording, impact speed).
    scores : list of dict
        Each shot's residuals before and after.
    intervals : list of dict, optional
        The law at its nodes with their 95 % intervals (``calibrate``'s): each node's
        ``velocity`` [m/s], ``value``, ``error``, ``low``, ``high`` [-] and ``weak``.
    """
    if not name or safe_name(name) != name:
        raise OptionError(f"--name: found {name!r}, expected a law name of letters, digits, "
                          "'-', '_' and '.' (such as LOT-2026-07)")
    record = {"name": name, "coefficients": list(law.coefficients),
              "v_range": list(law.v_range), "shots": shots, "scores": scores,
              **({"intervals": intervals} if intervals is not None else {}),
              **({"proposal": proposal} if proposal is not None else {}),
              "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
              "command": list(command)}
    with signals_held():  # the archive made and the law stored, or neither
        archive = Archive(root, create=True)
        version = archive.keep(_folder(root, name), record, "the law")
    return f"{name}@{version}"


def _law(record, ref, path):
    try:
        coefficients = [float(c) for c in record["coefficients"]]
        lo, hi = (float(v) for v in record["v_range"])
        if len(coefficients) != DEGREE + 1 or not lo < hi:
            raise ValueError
        return CrushLaw(tuple(coefficients), (lo, hi), "fitted", source=ref)
    except (KeyError, TypeError, ValueError):
        raise ArchiveError(f"{display(path)}: is not a crush law record, expected 7 "
                           "coefficients and a velocity range (see airgun-xl archive "
                           "verify)") from None


def load_law(root, ref):
    """The law ``NAME`` (its latest version) or ``NAME@N`` of the archive at ``root``, as a
    :class:`CrushLaw` whose ``source`` is its reference; and its record."""
    m = _REF.match(str(ref).strip())
    folder = _folder(root, m.group("name")) if m else None
    found = versions(folder) if folder is not None else []
    if m and m.group("version"):
        found = [v for v in found if v[0] == int(m.group("version"))]
    name = str(ref).strip().partition("@")[0]
    for version, path in reversed(found):  # the latest the archive holds (committed)
        record = read_record(root, path, "law")
        if committed(root, name, version, record):
            return _law(record, f"{name}@{version}", path), record
        if m and m.group("version"):
            raise OptionError(f"--crush-law: found {short(ref)}, a law stored by a next that "
                              "did not finish (no proposal of the lot names it), expected a "
                              "law of the archive")
    known = ", ".join(r["ref"] for r in list_laws(root)) or "none yet"
    raise OptionError(f"--crush-law: found {short(ref)}, expected workbook, legacy or a "
                      f"law in {display(root)} (stored by calibrate --archive --name; "
                      f"there: {known})")


def list_laws(root):
    """Every stored law version: ``[{"ref", "v_range", "shots", "created"}]``, by name."""
    out: list = []
    for folder, version, path in all_versions(Path(root) / LAWS):
        try:
            record = read_record(root, path, "law")
            _law(record, f"{folder.name}@{version}", path)  # a law fill could run
            if not committed(root, folder.name, version, record):
                continue  # a next that did not finish: not a law of the archive
            lo, hi = record["v_range"]
            out.append({"ref": f"{folder.name}@{version}", "v_range": [lo, hi],
                        "shots": len(record.get("shots", [])),
                        "created": str(record.get("created", ""))})
        except ArchiveError as exc:  # listed and named, not fatal
            out.append({"ref": f"{folder.name}@{version}", "v_range": None, "shots": 0,
                        "created": f"unreadable: {exc}"})
    return out


#: What ``--crush-law`` takes, besides a law of the archive's library.
BUILT_IN_LAWS = ("workbook", "legacy")


def check_law_source(crush_law, archive):
    """The archive folder ``crush_law`` is read from (None for the built-in ones), refused
    before any run where a library law is named with no archive (``archive``, else
    $AIRGUN_XL_ARCHIVE) or is not in it."""
    from .store import archive_dir

    if crush_law in BUILT_IN_LAWS:
        return None
    root = archive_dir(archive, required=False)
    if root is None:
        raise OptionError(f"--crush-law: found {short(crush_law)} without --archive, "
                          "expected workbook, legacy, or a law name with the archive that "
                          "holds it")
    load_law(root, crush_law)
    return root


def shot_with_law(path, crush_law="workbook", archive=None):
    """The shot at ``path`` running the crush law ``--crush-law`` names: ``workbook`` (its
    Crush law sheet's, else the macro's), ``legacy`` (the macro's, Eq. 8, whatever the sheet
    says: not read) or ``NAME[@N]`` of the library of ``archive`` (else
    $AIRGUN_XL_ARCHIVE).

    Raises
    ------
    airgun_xl.errors.OptionError
        A library law named with no archive, or not in it: before the workbook is read.
    """
    from ..shot import Shot

    root = check_law_source(crush_law, archive)
    shot = Shot.from_workbook(path, read_law=crush_law == "workbook")
    if root is not None:
        return shot.with_params(crush_law=load_law(root, crush_law)[0])
    law = shot.params.crush_law
    if crush_law == "workbook" and law.named:
        return _checked_name(shot, law, archive)
    return shot


def _checked_name(shot, law, archive):
    """The shot with its sheet's law named for the record (its ``source``: the archive's
    entry is then listed under that law's lot) when the archive holds that version with the
    same values; else the law unnamed, with a warning when an archive was there to say it."""
    from .store import archive_dir

    root = archive_dir(archive, required=False)
    unnamed = shot.with_params(crush_law=CrushLaw(law.coefficients, law.v_range, law.name))
    if root is None:
        return unnamed
    try:
        kept = load_law(root, law.named)[0]
    except (OptionError, ArchiveError):
        kept = None
    if kept is not None and (kept.coefficients, kept.v_range) == (law.coefficients,
                                                                   law.v_range):
        return shot.with_params(crush_law=kept)
    why = ("which the archive does not hold" if kept is None else
           "whose values in the archive differ from the sheet's")
    unnamed.warnings.append(f"the Crush law sheet names the law {law.named}, {why}: the "
                            "sheet's own law is run, named as the workbook's")
    return unnamed
