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
    "SRS quality factor": Idea("--srs-q", ("srs_q",), aliases=("--q",)),
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


class Alias(argparse.Action):
    """An old spelling: stores its value where the idea's one spelling does, and notes on
    stderr which spelling replaces it."""

    def __init__(self, option_strings, dest, idea: str = "", **kwargs):
        self.idea = idea
        kwargs.setdefault("help", f"old spelling of {spelling(idea)}, kept one release")
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from .messages import note

        note([old_spelling_note(option_string or self.dest, spelling(self.idea))])
        setattr(namespace, self.dest, values)
