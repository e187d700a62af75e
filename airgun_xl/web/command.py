"""``serve``'s request, declared once (issue 61): the archive, the host and the port, each
read by its grammar; and its run. Light: the command line's parser imports it, and the
server (Starlette, numpy) only once it runs."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..app import declared
from ..errors import OptionError


def a_host(value: Any, who: str) -> str:
    """An address to listen on: a host name or an IP address, as text."""
    if not isinstance(value, str) or not value.strip():
        raise OptionError(f"{who}: found {value!r}, expected a host name or an address")
    return value


def a_port(value: Any, who: str) -> int:
    """A TCP port: a whole number from 0 (any free port) to 65535."""
    try:
        return declared.a_whole(value, who, 0, 65535)
    except OptionError:
        raise OptionError(f"{who}: found {value!r}, expected a port from 0 to 65535") from None


@dataclass(frozen=True, kw_only=True)
class ServeRequest(declared.Checked):
    """The view of ``archive`` (None: $AIRGUN_XL_ARCHIVE) on ``host``:``port``. Declared
    once (:mod:`airgun_xl.app.declared`): the command's options and the API's keywords."""

    archive: str | None = declared.the_archive()
    host: str = declared.option("127.0.0.1", "--host", read=a_host,
                                help="address to listen on (default 127.0.0.1, this machine "
                                     "only)")
    port: int = declared.option(8765, "--port", read=a_port,
                                help="port to listen on (default 8765; 0: any free port)")


def run(request: ServeRequest, say: Callable[[str], Any] = print) -> None:
    """Serve the view ``request`` asks for until Ctrl-C (:func:`serve`).

    Raises
    ------
    OptionError
        No archive given nor set in $AIRGUN_XL_ARCHIVE, and :func:`serve`'s.
    """
    from ..app.archive import archive_root

    root = archive_root(request.archive)
    if root is None:
        raise declared.refusal("{0}: found no archive, expected {0} DIR (or "
                               "$AIRGUN_XL_ARCHIVE)", "archive")
    from .server import serve

    serve(root, request.host, request.port, say)
