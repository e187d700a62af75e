"""The index's agent: a helper process that holds a server archive's connections, so that
psycopg's import (about 0.1 s of one core) runs beside the fill on the other core, started
before the fill needs it, instead of inside the fill.

The agent is this process's child, one a process, started on first use (or early, by
:func:`prestart`). It speaks one JSON object a line on its standard input and output: a
request ``{"op": ..., ...}``, a reply ``{"ok": ...}`` or ``{"error": {"kind", "message",
"broken"}}``. It imports psycopg, holds any number of connections by number, and runs the
statements it is sent, with their values as parameters. It ends when its input closes: when
this process ends, however it ends (a SIGKILL included), its connections close, and the server
rolls back what they had not committed and frees their locks.

:class:`Link` is one connection as the index uses it; :class:`LinkError` is a failure, in
libpq's words, on one line.
"""
from __future__ import annotations

import atexit
import contextlib
import json
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

if TYPE_CHECKING:
    import subprocess

#: The longest reply line read from the agent [bytes] (a history of some 500,000 entries).
MAX_REPLY = 256 * 2**20

class LinkError(Exception):
    """A failure on the server or in the agent.

    Attributes
    ----------
    kind : str
        ``missing`` (psycopg is not installed), ``address`` (libpq cannot read the address),
        ``connect`` (the server cannot be reached), ``login`` (it refused the login: a wrong
        password, an unknown role), ``unique`` (a unique
        constraint), ``undefined`` (no such table or schema), ``lost`` (the agent stopped),
        ``other``.
    message : str
        What went wrong, on one line (libpq's message; never the address's secrets).
    broken : bool
        Whether the connection is unusable now.
    """

    def __init__(self, kind: str, message: str, broken: bool = False):
        super().__init__(message)
        self.kind, self.message, self.broken = kind, message, broken


def _reason(exc):
    """An error in words, on one line, at most 300 characters."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text[:300]


def _libpq_reads(name):
    """Whether libpq reads the environment variable ``name`` (its ``PG*`` settings, and where
    ``.pgpass`` and the service file are looked for)."""
    return name.startswith("PG") or name in ("HOME", "APPDATA", "USERPROFILE")


# -- the agent's side ---------------------------------------------------------------------------

#: The libpq keywords an address may hold: where the server is, who logs in, how the
#: connection is secured and kept alive. Not ``password`` nor ``sslpassword`` (SECRETS: the
#: command line is recorded with every entry and shown by ps), nor ``options`` (the tool's
#: own session settings, its timeouts, would be overridden) nor ``replication``.
ALLOWED_KEYWORDS = frozenset((
    "host", "hostaddr", "port", "dbname", "user", "passfile", "require_auth",
    "channel_binding", "connect_timeout", "client_encoding", "application_name",
    "fallback_application_name", "keepalives", "keepalives_idle", "keepalives_interval",
    "keepalives_count", "tcp_user_timeout", "gssencmode", "sslmode", "sslcompression",
    "sslcert", "sslkey", "sslrootcert", "sslcrl", "sslcrldir", "sslsni", "sslcertmode",
    "ssl_min_protocol_version", "ssl_max_protocol_version", "requirepeer", "krbsrvname",
    "gsslib", "gssdelegation", "service", "target_session_attrs", "load_balance_hosts"))

#: The keywords that carry a secret: refused, their values never repeated.
SECRETS = ("password", "sslpassword")


def _handle(psycopg, conns, request):
    op = request["op"]
    if op == "parse":  # libpq reads the address; only what messages show comes back
        from psycopg.conninfo import conninfo_to_dict

        try:
            parts = conninfo_to_dict(request["address"])
        except Exception:
            raise LinkError("address", "libpq cannot read the address") from None
        shown = {k: parts.get(k) for k in ("host", "hostaddr", "port", "dbname", "service")}
        secrets = [k for k in SECRETS if k in parts]
        unknown = sorted(k for k in parts if k not in ALLOWED_KEYWORDS and k not in SECRETS)
        return dict(shown, password=bool(secrets), secrets=secrets, unknown=unknown[:5])
    if op == "connect":
        parsed = _handle(psycopg, conns, {"op": "parse", "address": request["address"]})
        if parsed["secrets"] or parsed["unknown"]:  # refused by the allow-list, never dialled
            raise LinkError("address", "found a keyword the address may not hold")
        for name in [n for n in os.environ if _libpq_reads(n)]:  # this process's, as now
            del os.environ[name]
        os.environ.update(request["env"])
        try:
            conn = psycopg.connect(request["address"], connect_timeout=10,
                                   application_name="airgun-xl", options=request["options"])
        except psycopg.Error as exc:  # SQLSTATE class 28: the server refused the login
            login = str(getattr(exc, "sqlstate", "") or "").startswith("28") or \
                "authentication failed" in str(exc)
            raise LinkError("login" if login else "connect", _reason(exc), True) from None
        number = max(conns, default=0) + 1
        conns[number] = conn
        return number
    conn = conns.get(request["conn"])
    if conn is None:
        raise LinkError("other", "the connection was closed", True)
    if op == "close":
        del conns[request["conn"]]
        with contextlib.suppress(Exception):
            conn.close()
        return None
    if op in ("commit", "rollback"):
        getattr(conn, op)()
        return None
    if op == "many":
        with conn.cursor() as cur:
            cur.executemany(request["sql"], request["seq"])
        return None
    with conn.transaction() if request.get("savepoint") else contextlib.nullcontext():
        cur = conn.execute(request["sql"], request["args"])
        if cur.description is None:
            return {"columns": [], "rows": []}
        return {"columns": [d.name for d in cur.description],
                "rows": [list(r) for r in cur.fetchall()]}


def _error(psycopg, conns, request, exc):
    conn = conns.get(request.get("conn"))
    broken = conn is None or conn.closed or conn.broken
    if isinstance(exc, LinkError):
        return {"kind": exc.kind, "message": exc.message, "broken": exc.broken or broken}
    kind = "other"
    if psycopg is not None and isinstance(exc, psycopg.errors.UniqueViolation):
        kind = "unique"
    elif psycopg is not None and isinstance(exc, (psycopg.errors.UndefinedTable,
                                                  psycopg.errors.InvalidSchemaName)):
        kind = "undefined"
    return {"kind": kind, "message": _reason(exc), "broken": broken}


def serve(stdin=None, stdout=None):
    """The agent's loop: a request a line in, a reply a line out, until the input closes."""
    import signal

    with contextlib.suppress(ValueError, OSError):  # an interrupt is the parent's to handle
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    stdin = stdin or sys.stdin.buffer
    stdout = stdout or sys.stdout.buffer
    sys.stdout = sys.stderr  # a stray print goes where the parent does not read
    psycopg: Any = None
    with contextlib.suppress(ImportError):
        import psycopg
    conns: dict[int, Any] = {}
    try:
        for line in stdin:
            request: dict = {}
            try:
                request = json.loads(line)
                if psycopg is None:
                    raise LinkError("missing", "psycopg is not installed")
                reply: dict = {"ok": _handle(psycopg, conns, request)}
            except Exception as exc:
                reply = {"error": _error(psycopg, conns, request, exc)}
            if request.get("op") == "close":
                continue  # told, not asked: no reply
            stdout.write(json.dumps(reply, default=str).encode() + b"\n")
            stdout.flush()
    finally:
        for conn in conns.values():
            with contextlib.suppress(Exception):
                conn.close()


# -- this process's side ------------------------------------------------------------------------

class Agent:
    """The agent process, and the calls made to it (one at a time)."""

    def __init__(self):
        import subprocess  # here: the archive's light commands do not pay for it
        import threading

        # this file alone, run as a module of its own: the agent imports the standard library
        # and psycopg, not airgun_xl (its start is what a fill waits for)
        code = ("import importlib.util as u; s = u.spec_from_file_location('airgun_xl_agent', "
                f"{str(Path(__file__).resolve())!r}); m = u.module_from_spec(s); "
                "s.loader.exec_module(m); m.serve(); m.os._exit(0)")  # no teardown to wait on
        self.pid = os.getpid()
        try:
            self.proc: subprocess.Popen | None = subprocess.Popen(
                [sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL)
        except (OSError, ValueError) as exc:
            raise LinkError("lost", f"the index's helper process cannot be started ({exc})",
                            True) from None
        self.lock = threading.Lock()
        self.unused: list[int] = []  # connections dropped unclosed: closed before the next call
        self.ahead: list[str] = []  # requests sent ahead whose replies are still to be read
        self.early: dict[str, dict] = {}  # replies to requests sent ahead, read

    def call(self, op: str, **fields: Any) -> Any:
        """Send one request; return its reply's result.

        Raises
        ------
        LinkError
        """
        with self.lock:
            self._prepare()
            self._send(dict(fields, op=op))
            try:
                line = self._read()
            except BaseException as exc:
                if not isinstance(exc, LinkError):  # an interrupt between request and reply:
                    self.stop(kill=True)  # its reply would answer the next request
                raise
            return self._result(line)

    def tell(self, op: str, **fields: Any) -> None:
        """Send a request that has no reply (``close``)."""
        with self.lock:
            self._prepare()
            self._send(dict(fields, op=op))

    def ahead_of_time(self, op: str, **fields: Any) -> None:
        """Send a request now, its reply to be taken later by :meth:`take`."""
        request = dict(fields, op=op)
        key = json.dumps(request, sort_keys=True)
        with self.lock:
            if key in self.ahead or key in self.early:
                return  # sent already, not taken yet
            self._send(request)
            self.ahead.append(key)

    def take(self, op: str, **fields: Any) -> Any:
        """The result of the same request sent ahead of time; :meth:`call` if none was."""
        key = json.dumps(dict(fields, op=op), sort_keys=True)
        with self.lock:
            self._prepare()
            if key in self.early:
                return self._result(self.early.pop(key))
        return self.call(op, **fields)

    def _prepare(self):
        """Read the replies sent ahead, and close what was dropped unclosed."""
        while self.ahead:
            try:
                reply = self._read()
            except BaseException as exc:
                if not isinstance(exc, LinkError):
                    self.stop(kill=True)
                raise
            self.early[self.ahead.pop(0)] = reply
        while self.unused:
            self._send({"op": "close", "conn": self.unused.pop()})

    def _send(self, request):
        proc = self.proc
        try:
            if proc is None or proc.stdin is None:
                raise OSError
            proc.stdin.write(json.dumps(request).encode() + b"\n")
            proc.stdin.flush()
        except (OSError, ValueError):
            self._lost()

    def _read(self):
        proc = self.proc
        line = b""
        if proc is not None and proc.stdout is not None:
            with contextlib.suppress(OSError, ValueError):
                line = proc.stdout.readline(MAX_REPLY)
        try:
            if line.endswith(b"\n"):
                return json.loads(line)
        except ValueError:
            pass
        self._lost()

    def _lost(self) -> NoReturn:
        self.stop(kill=True)
        raise LinkError("lost", "the index's helper process stopped (or sent more than "
                                f"{MAX_REPLY >> 20} MiB, or not a reply)", True)

    def _result(self, reply):
        if isinstance(reply, dict) and isinstance(reply.get("error"), dict):
            error = reply["error"]
            raise LinkError(str(error.get("kind")), str(error.get("message")),
                            bool(error.get("broken")))
        if not isinstance(reply, dict) or "ok" not in reply:
            self._lost()
        return reply["ok"]

    def stop(self, kill=False):
        """Close the agent's input (it closes its connections and ends) and reap it; with
        ``kill``, end it now (the server closes its sessions)."""
        proc, self.proc = self.proc, None
        self.ahead.clear()
        self.early.clear()
        if proc is None:
            return
        if kill:
            with contextlib.suppress(OSError):
                proc.kill()
        for stream in (proc.stdin, proc.stdout):
            with contextlib.suppress(Exception):
                stream.close()  # type: ignore[union-attr]
        import subprocess

        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()

    @property
    def running(self) -> bool:
        return self.proc is not None and self.proc.poll() is None and self.pid == os.getpid()


_AGENT: list[Agent] = []


def agent() -> Agent:
    """This process's agent, started if it is not running."""
    if _AGENT and _AGENT[0].running:
        return _AGENT[0]
    if _AGENT and _AGENT[0].pid == os.getpid():
        _AGENT[0].stop()
    _AGENT[:] = [Agent()]
    return _AGENT[0]


def prestart(address: str | None = None, options: str | None = None) -> None:
    """Start the agent now, so that its import of psycopg runs while this process works;
    with ``address``, connect ahead of time too (:class:`Link` takes that connection)."""
    with contextlib.suppress(LinkError):
        helper = agent()
        if address is not None and options is not None:
            helper.ahead_of_time("connect", **_connect_request(address, options))


def _connect_request(address, options):
    """A ``connect`` request's fields: libpq's environment as this process has it now."""
    return {"address": address, "options": options,
            "env": {k: v for k, v in os.environ.items() if _libpq_reads(k)}}


@atexit.register
def stop() -> None:
    """Stop this process's agent (its connections close); the next use starts another."""
    if _AGENT and _AGENT[0].pid == os.getpid():
        _AGENT.pop().stop()


class Result:
    """A statement's rows (a cursor's, already fetched)."""

    def __init__(self, reply):
        self.columns: list[str] = reply["columns"]
        self.rows: list[list] = reply["rows"]

    def fetchone(self):
        return tuple(self.rows[0]) if self.rows else None

    def fetchall(self):
        return [tuple(r) for r in self.rows]

    def dicts(self):
        return [dict(zip(self.columns, r, strict=True)) for r in self.rows]

    def __iter__(self):
        return iter(self.fetchall())


class Link:
    """One connection to the server, held by the agent.

    Parameters
    ----------
    address : str
        libpq's address (no password: :func:`airgun_xl.archive.index.server_address`).
    options : str
        The session's settings (``-c statement_timeout=...``).
    """

    def __init__(self, address: str, options: str, fresh: bool = False):
        self.agent = agent()
        request = _connect_request(address, options)
        self.number = (self.agent.call("connect", **request) if fresh
                       else self.agent.take("connect", **request))
        self.broken = False

    @property
    def closed(self) -> bool:
        return self.number is None

    def _call(self, op, **fields):
        if self.number is None:
            raise LinkError("other", "the connection was closed", True)
        try:
            return self.agent.call(op, conn=self.number, **fields)
        except LinkError as exc:
            self.broken = self.broken or exc.broken
            raise

    def execute(self, sql: str, args=(), savepoint: bool = False) -> Result:
        """Run one statement (inside a savepoint: its failure leaves the transaction
        standing); return its rows."""
        return Result(self._call("execute", sql=sql, args=list(args), savepoint=savepoint))

    def executemany(self, sql: str, seq) -> None:
        self._call("many", sql=sql, seq=[list(args) for args in seq])

    def commit(self) -> None:
        self._call("commit")

    def rollback(self) -> None:
        self._call("rollback")

    def close(self) -> None:
        number, self.number = self.number, None
        if number is not None and self.agent.running:
            with contextlib.suppress(LinkError):
                self.agent.tell("close", conn=number)

    def __del__(self):
        if getattr(self, "number", None) is not None:  # closed before the agent's next call
            self.agent.unused.append(self.number)

