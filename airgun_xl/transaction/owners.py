"""Who owns a temp file: a process named by its pid, its start time and its host, so that a
reused pid does not look like the owner, and a process of another host sharing the folder is
never taken for a dead one of this host. psutil reads the pid and start time on every
platform the wheels go to (on Windows, ``os.kill(pid, 0)`` would send CTRL_C_EVENT instead of
testing for the process)."""
import os
import re
import socket

#: An owner token as a file name holds it: ``<pid>.<start>`` and, since issue 36, ``.<host>``.
OWNER_PATTERN = r"\d+\.\d+(?:\.[a-z][a-z0-9]{0,31})?"


def host_tag(name=None):
    """This host's name as a token carries it: lower-case letters and digits, at most 32,
    starting with a letter (``LAB-Cell.2`` -> ``labcell2``, ``42`` -> ``h42``), so that a
    file name's owner reads one way only."""
    text = re.sub(r"[^a-z0-9]", "", (name if name is not None else socket.gethostname())
                  .lower())
    if not text[:1].isalpha():
        text = "h" + text
    return text[:32]


def _start_time(pid):
    """A process's start time in centiseconds since the epoch, 0 when it is gone or unknown."""
    import psutil  # here: the CLI's start does not pay for it

    try:
        return int(psutil.Process(pid).create_time() * 100)
    except (psutil.Error, OSError, ValueError, OverflowError):
        return 0


def owner_token():
    """This process as ``<pid>.<start time>.<host>``: a reused pid does not look like its
    owner, and another host's process is not looked for among this host's."""
    pid = os.getpid()
    return f"{pid}.{_start_time(pid)}.{host_tag()}"


def owner_host(token):
    """The host an owner token names, or None for a token of before issue 36 (this host's)."""
    parts = token.split(".")
    return parts[2] if len(parts) == 3 else None


def owner_alive(token):
    """Whether the process an :func:`owner_token` names is still running: its pid exists and,
    when the token has a start time, started then (a later process with the same pid is not
    the owner). A process of another host is taken to be running: this host cannot see it,
    and only a server that can (a server archive's index) may say that it is gone."""
    import psutil

    host = owner_host(token)
    if host is not None and host != host_tag():
        return True
    pid_text, _, started = token.partition(".")
    started = started.split(".")[0]
    try:
        pid = int(pid_text)
        if pid <= 0 or not psutil.pid_exists(pid):
            return False
    except (ValueError, OverflowError):
        return False
    now = _start_time(pid)
    return not (now and started.isdigit() and int(started) and now != int(started))
