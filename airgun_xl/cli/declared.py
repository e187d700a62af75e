"""A command's options built from its request's declaration (issue 61;
:mod:`airgun_xl.app.declared`): one ``add_argument`` a field, in the fields' order, its value
read by the field's own grammar naming the flag; and the request from what was parsed."""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
from collections.abc import Iterator
from typing import Any

from ..app.declared import option_of
from ..errors import OptionError
from .cfc_option import CfcOption, cfc_value
from .run_options import Integrators
from .vocabulary import Alias, One


def _typed(read: Any, flag: str) -> Any:
    """argparse's ``type``: the field's grammar, a refusal naming ``flag``."""
    def parse(text: str) -> Any:
        return read(text, flag)
    parse.__name__ = flag.lstrip("-").replace("-", "_")  # argparse names it in its messages
    return parse


def add_declared(original: argparse.ArgumentParser, request: type, skip: tuple[str, ...] = (),
                 only: tuple[str, ...] | None = None) -> None:
    """Each field of the dataclass ``request`` (but ``skip``; with ``only``, those alone) as
    ``original``'s argument, in the fields' order (a command whose help shows an option of its
    own between them adds them in two calls); fields of one group exclude each other."""
    groups: dict[str, Any] = {}
    for field in dataclasses.fields(request):
        if field.name in skip or (only is not None and field.name not in only):
            continue
        spelt = option_of(field)
        parser: Any = original
        if spelt.group is not None:  # options that exclude each other
            if spelt.group not in groups:
                groups[spelt.group] = original.add_mutually_exclusive_group()
            parser = groups[spelt.group]
        _add_field(parser, field, spelt)
        flag = spelt.flags[-1]
        for alias, idea in spelt.aliases:
            original.add_argument(alias, type=_typed(field.metadata["read"], flag),
                                  dest=field.name, metavar=spelt.metavar, action=Alias,
                                  idea=idea)


def _add_field(parser: Any, field: dataclasses.Field[Any], spelt: Any) -> None:
    """One field as ``parser``'s argument, by the kind of option it is spelt as."""
    flag = spelt.flags[-1]
    if spelt.kind == "positional":
        parser.add_argument(field.name, metavar=spelt.metavar, help=spelt.help,
                            choices=spelt.choices or None)
    elif spelt.kind == "positional?":
        parser.add_argument(field.name, nargs="?", metavar=spelt.metavar, help=spelt.help)
    elif spelt.kind == "switch":
        parser.add_argument(*spelt.flags, action="store_true", help=spelt.help)
    elif spelt.kind == "choice":
        parser.add_argument(*spelt.flags, choices=spelt.choices, default=field.default,
                            help=spelt.help)
    elif spelt.kind == "integrators":  # each given once more, into a list
        assert isinstance(field.default, tuple), field.name
        parser.add_argument(*spelt.flags, action=Integrators, default=list(field.default),
                            metavar=spelt.metavar, help=spelt.help, dest=field.name)
    elif spelt.kind == "repeated":  # given once for each value, read together
        parser.add_argument(*spelt.flags, action="append", default=[],
                            metavar=spelt.metavar, help=spelt.help, dest=field.name)
    elif spelt.kind == "cfc":  # argparse's own line, as every command's --cfc gives
        parser.add_argument(*spelt.flags, type=cfc_value, default=field.default,
                            metavar=spelt.metavar, action=CfcOption, help=spelt.help)
    else:
        parser.add_argument(*spelt.flags, type=_typed(field.metadata["read"], flag),
                            default=field.default, metavar=spelt.metavar, action=One,
                            help=spelt.help, dest=field.name)


def request_of(request: type, args: argparse.Namespace, **given: Any) -> Any:
    """The ``request`` of the parsed ``args`` (each field from its own dest; ``given``
    overrides, such as an output's default name); a refusal of the request's own checks
    names the field's flag, as every command-line refusal does."""
    fields = dataclasses.fields(request)
    values = {f.name: given[f.name] if f.name in given else getattr(args, f.name)
              for f in fields}
    with flags_named(request):
        return request(**values)


def _spelt(spelt: Any) -> str:
    """How the command line names an option: its flag, or a positional's metavar
    (``ENTRY``)."""
    if spelt.kind in ("positional", "positional?") and spelt.metavar:
        return str(spelt.metavar)
    return str(spelt.flags[-1])


@contextlib.contextmanager
def flags_named(request: type) -> Iterator[None]:
    """A refusal that names fields of ``request`` (``q: ...``; of two fields together,
    ``lo/hi: ...``), raised while making it or running it, said with their flags instead
    (``--srs-q: ...``; a positional by its metavar, ``ENTRY: ...``)."""
    try:
        yield
    except OptionError as exc:
        prefix, colon, rest = str(exc).partition(": ")
        flags = {f.name: _spelt(option_of(f)) for f in dataclasses.fields(request)}
        if exc.template is not None and all(name in flags for name in exc.fields):
            raise OptionError(exc.template.format(*(flags[n] for n in exc.fields),
                                                  **exc.values)) from None
        names = prefix.split("/")
        if colon and all(name in flags for name in names):
            raise OptionError("/".join(flags[n] for n in names) + ": " + rest) from None
        raise
