"""Who owns a temp file: a process named by its pid and start time, so that a reused pid
does not look like the owner. psutil reads both on every platform the wheels go to (on
Windows, ``os.kill(pid, 0)`` would send CTRL_C_EVENT instead of testing for the process)."""
import os


def _start_time(pid):
    """A process's start time in centiseconds since the epoch, 0 when it is gone or unknown."""
    import psutil  # here: the CLI's start does not pay for it

    try:
        return int(psutil.Process(pid).create_time() * 100)
    except (psutil.Error, OSError, ValueError, OverflowError):
        return 0


def owner_token():
    """This process as ``<pid>.<start time>``: a reused pid does not look like its owner."""
    pid = os.getpid()
    return f"{pid}.{_start_time(pid)}"


def owner_alive(token):
    """Whether the process an :func:`owner_token` names is still running: its pid exists and,
    when the token has a start time, started then (a later process with the same pid is not
    the owner)."""
    import psutil

    pid_text, _, started = token.partition(".")
    try:
        pid = int(pid_text)
        if pid <= 0 or not psutil.pid_exists(pid):
            return False
    except (ValueError, OverflowError):
        return False
    now = _start_time(pid)
    return not (now and started.isdigit() and int(started) and now != int(started))
