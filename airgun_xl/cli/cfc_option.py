"""``--cfc N|none`` and its old spelling ``--record``: the record judged, given once by any
of its spellings (the recording's options, the specification's and the declared commands'
share it)."""
import argparse

from ..specification import CFC_CLASSES
from .vocabulary import Alias


def cfc_value(text):
    """``--cfc``: a SAE J211 class, or ``none`` for no filter (None)."""
    from ..app.specifying import cfc_class

    try:
        return cfc_class(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def record_value(text):
    """``--record`` (the old spelling of ``--cfc``): ``unfiltered`` or ``cfcN``, as the
    Specification sheet writes the record judged."""
    value = text.strip().lower().replace(" ", "")
    if value == "unfiltered":
        return None
    if value.startswith("cfc") and value[3:].isdigit() and int(value[3:]) in CFC_CLASSES:
        return int(value[3:])
    raise argparse.ArgumentTypeError(f"found {text!r}, expected unfiltered or one of 60, 180,"
                                     " 600, 1000 (cfc600)")


def _given(namespace, option_string, value):
    """Store the class, and which option gave it; the filter given twice, by any of its
    spellings, differently, is refused (the last would otherwise win unseen)."""
    from ..errors import OptionError

    seen = getattr(namespace, "_given", None) or {}
    if "cfc" in seen and seen["cfc"][1] != value:
        def shown(cfc):
            return "none" if cfc is None else str(cfc)

        first = seen["cfc"][0]
        again = "again" if first == option_string else f"where {first} gave it"
        raise OptionError(f"{option_string}: found {shown(value)}, {again} "
                          f"({shown(seen['cfc'][1])}); expected the filter once (--cfc)")
    seen["cfc"] = (option_string, value)
    namespace._given = seen
    namespace.cfc = value
    namespace.cfc_given = option_string


class CfcOption(argparse.Action):
    """``--cfc N|none``: stores the class (None for none) and which option gave it, so that
    ``--cfc none`` judges the unfiltered record over a specification's class."""

    def __call__(self, parser, namespace, values, option_string=None):
        _given(namespace, option_string or "--cfc", values)


class RecordAlias(Alias):
    """``--record unfiltered|cfcN``: the old spelling of ``--cfc``, kept one release."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, idea="recording's filter", **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from .messages import later
        from .vocabulary import old_spelling_note, spelling

        _given(namespace, option_string or "--record", values)
        later([old_spelling_note(option_string or "--record", spelling(self.idea))])
