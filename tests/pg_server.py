"""A real PostgreSQL server for the tests of a server archive (issue 36), started from the
server's own binaries (initdb, pg_ctl): no mock.

- initdb refuses to run as root, so under root the server runs as an unprivileged user
  (``postgres`` where Debian's package made one, else ``nobody``);
- its socket folder is short (``/tmp/agx-pg-XXXX``): Unix socket paths stop near 107 bytes;
- it listens on the loopback on a free port, with password (SCRAM) authentication over TCP;
- two roles, as README's administrator block makes them (issue 43): ``lab_admin`` owns
  schema ``airgun_xl`` (it makes and migrates the archives' tables: ``archive init --index
  ... --writers lab``), and ``lab``, the engineers', may use the schema and, once an archive
  is made, read its tables and add entries, nothing more; neither is a superuser.

Without the binaries or psycopg, the tests skip with one line saying what to install.
"""
from __future__ import annotations

import glob
import os
import pwd
import shutil
import socket
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

#: The archive role's password, given to libpq by $PGPASSWORD only (never in an address).
PASSWORD = "lab-secret-36"

WHY_SKIPPED = ("needs PostgreSQL's server binaries (initdb, pg_ctl): apt-get install "
               "postgresql; and psycopg: pip install -e '.[test]'")


def binaries():
    """The folder of initdb and pg_ctl: on PATH, else Debian's /usr/lib/postgresql/N/bin
    (the newest); None when absent."""
    found = shutil.which("initdb")
    if found and shutil.which("pg_ctl"):
        return Path(found).resolve().parent
    for folder in sorted(glob.glob("/usr/lib/postgresql/*/bin"),
                         key=lambda p: int(Path(p).parent.name)
                         if Path(p).parent.name.isdigit() else 0, reverse=True):
        if os.access(Path(folder) / "initdb", os.X_OK):
            return Path(folder)
    return None


def available():
    try:
        import psycopg  # noqa: F401
    except ImportError:
        return False
    return binaries() is not None


@dataclass
class Server:
    """A running server: its address for the archive's role (no password in it), the
    superuser's socket address, and how to stop and start it."""

    bin: Path
    data: Path
    socket_dir: Path
    port: int
    user: str | None

    @property
    def address(self) -> str:
        """The engineers' role: SELECT and INSERT."""
        return f"postgresql://lab@127.0.0.1:{self.port}/lab"

    @property
    def owner_address(self) -> str:
        """The administrator's role, the schema's owner."""
        return f"postgresql://lab_admin@127.0.0.1:{self.port}/lab"

    @property
    def admin(self) -> str:
        return f"host={self.socket_dir} port={self.port} user=admin dbname=postgres"

    def _run(self, *args, check=True, timeout=120):
        kwargs = {}
        if self.user is not None:
            record = pwd.getpwnam(self.user)
            kwargs = {"user": record.pw_uid, "group": record.pw_gid, "extra_groups": []}
        return subprocess.run([str(self.bin / args[0]), *map(str, args[1:])],
                              capture_output=True, text=True, check=check, timeout=timeout,
                              cwd="/", **kwargs)

    def start(self):
        self._run("pg_ctl", "-D", self.data, "-l", self.data / "log", "-w", "-t", "60", "-o",
                  f"-p {self.port} -k {self.socket_dir} -c listen_addresses=127.0.0.1 "
                  "-c fsync=off -c max_connections=60", "start")

    def stop(self, mode="fast"):
        self._run("pg_ctl", "-D", self.data, "-m", mode, "-w", "stop", check=False)

    def sql(self, *statements):
        """Run statements as the superuser (autocommit)."""
        import psycopg

        with psycopg.connect(self.admin, autocommit=True) as conn:
            for statement in statements:
                conn.execute(statement)


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server():
    """initdb, configure and start a server; return its :class:`Server`."""
    folder = Path(tempfile.mkdtemp(prefix="agx-pg-", dir="/tmp"))  # a short socket path
    user = None
    if os.geteuid() == 0:
        user = "postgres" if _has_user("postgres") else "nobody"
        record = pwd.getpwnam(user)
        os.chown(folder, record.pw_uid, record.pw_gid)
    server = Server(binaries(), folder / "data", folder, _free_port(), user)
    server._run("initdb", "-D", server.data, "-U", "admin", "-A", "trust", "--no-sync",
                "-E", "UTF8", "--locale=C")
    with open(server.data / "pg_hba.conf", "w") as fh:
        fh.write("local all admin trust\n"
                 "host all all 127.0.0.1/32 scram-sha-256\n")
    if user is not None:
        record = pwd.getpwnam(user)
        os.chown(server.data / "pg_hba.conf", record.pw_uid, record.pw_gid)
    server.start()
    server.sql(f"CREATE ROLE lab LOGIN PASSWORD '{PASSWORD}'",
               f"CREATE ROLE lab_admin LOGIN PASSWORD '{PASSWORD}'",
               "CREATE DATABASE lab",
               "REVOKE ALL ON DATABASE lab FROM PUBLIC",
               "GRANT CONNECT ON DATABASE lab TO lab, lab_admin")
    import psycopg

    with psycopg.connect(server.admin.replace("dbname=postgres", "dbname=lab"),
                         autocommit=True) as conn:
        conn.execute("REVOKE ALL ON SCHEMA public FROM PUBLIC")
        conn.execute("CREATE SCHEMA airgun_xl AUTHORIZATION lab_admin")
        conn.execute("GRANT USAGE ON SCHEMA airgun_xl TO lab")
    return server


def _has_user(name):
    try:
        pwd.getpwnam(name)
    except KeyError:
        return False
    return True


def remove_server(server):
    server.stop("immediate")
    shutil.rmtree(server.socket_dir, ignore_errors=True)
