"""One vocabulary across the commands (issue 35), declared once.

Each idea that more than one command names has one spelling here, the names argparse stores
it under (its dests), and the old spellings kept one release as aliases. An alias still
works, and says on stderr, once, which spelling replaces it. ``tests/test_cli_vocabulary.py``
walks every subcommand's parser against this table: an idea spelt two ways that are not
declared here fails it.
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass


@dataclass(frozen=True)
class Idea:
    """An idea of the command line.

    Parameters
    ----------
    spelling : str
        Its one option (``--srs-q``), or a positional's metavar (``RECORDING``).
    dests : tuple of str
        Where argparse stores it, in any subcommand.
    aliases : tuple of str
        Old spellings, each kept one release through :class:`Alias` (a positional one
        through its command's own check).
    subjects : tuple of str
        Commands that take it as their positional subject instead (``archive verify DIR``).
    """

    spelling: str
    dests: tuple[str, ...]
    aliases: tuple[str, ...] = ()
    subjects: tuple[str, ...] = ()


VOCABULARY = {
    "archive folder": Idea("--archive", ("archive", "dir"), aliases=("DIR",),
                           subjects=("archive",)),
    "SRS quality factor": Idea("--srs-q", ("srs_q", "q"), aliases=("--q",)),
    "recording's filter": Idea("--cfc", ("cfc",), aliases=("--record",)),
    "recording": Idea("RECORDING", ("recording", "measured")),
    "recording's sign": Idea("--sign", ("sign",)),
    "seed of the draws": Idea("--seed", ("seed",)),
    "integrator": Idea("--integrator", ("integrator",)),
    "relative tolerance": Idea("--rtol", ("rtol",)),
    "absolute tolerance": Idea("--atol", ("atol",)),
    "JSON on stdout": Idea("--json", ("json",)),
    "report workbook": Idea("--report", ("report",)),
    "replace an existing output": Idea("--force", ("force",)),
}


def spelling(idea: str) -> str:
    """The one spelling of ``idea`` (a key of :data:`VOCABULARY`)."""
    return VOCABULARY[idea].spelling


def old_spelling_note(old: str, new: str) -> str:
    """The line an old spelling prints."""
    return f"{old} is the old spelling of {new}, kept until the next release: write {new}"


def given(namespace, dest, option, value, once=False):
    """Store ``value`` at ``dest`` for ``option``, refusing a second value for the same idea
    (by any of its spellings, or by the same one: the last would win unseen); with ``once``
    (a specification's field), a second time at all.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    from ..errors import OptionError

    seen = getattr(namespace, "_given", None)
    if seen is None:
        seen = {}
        setattr(namespace, "_given", seen)
    if dest in seen:
        first, earlier = seen[dest]
        if once or earlier != value:
            again = "again" if first == option else f"where {first} gave it"
            raise OptionError(f"{option}: found {_shown(value)}, {again} ({_shown(earlier)}); "
                              "expected it once")
    seen[dest] = (option, value)
    setattr(namespace, dest, value)


def _shown(value):
    text = repr(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 40 else f"{text[:30]}..."


class Once(argparse.Action):
    """A specification's field: given once (a second ``--peak`` is refused, as a second
    ``--sd`` is), an empty value refused."""

    def __call__(self, parser, namespace, values, option_string=None):
        option = option_string or self.dest
        _not_empty(option, values)
        given(namespace, self.dest, option, values, once=True)


class One(argparse.Action):
    """An idea's one spelling: a second, different value for it, by this spelling or an
    old one, is refused."""

    def __call__(self, parser, namespace, values, option_string=None):
        option = option_string or self.dest
        _not_empty(option, values)
        given(namespace, self.dest, option, values)


def _not_empty(option, values):
    """An option given an empty value (``--archive=``) is refused: it would stand for none
    (:func:`airgun_xl.app.specifying.not_empty`, as the Python API refuses it)."""
    from ..app.specifying import not_empty

    not_empty(option, values)


class Alias(argparse.Action):
    """An old spelling: stores its value where the idea's one spelling does (a different
    value from its one spelling's refused), and notes on stderr, once the command has
    succeeded, which spelling replaces it."""

    def __init__(self, option_strings, dest, idea: str = "", **kwargs):
        self.idea = idea
        kwargs.setdefault("help", f"old spelling of {spelling(idea)}, kept one release")
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from .messages import later

        option = option_string or self.dest
        _not_empty(option, values)
        given(namespace, self.dest, option, values)
        later([old_spelling_note(option, spelling(self.idea))])
