"""Stopping a command from outside: Ctrl-C (SIGINT) and SIGTERM (``timeout``, a batch
scheduler's cancel, ``docker stop``, systemd).

The command line (``identification.cli.arguments.main``) runs each command under :func:`signals_raise`:
either signal raises :class:`Interrupted` in the main thread, the engines terminate their
workers on the way out (``identification.fitting.engine``), and ``main`` prints one line, ``interrupted:
nothing written`` or the files already written (:func:`record_written`), and returns 128 + the
signal's number (130, 143), the shell's convention for a command ended by a signal.

Outputs are written whole or not at all: :func:`atomic_path` writes a file beside its target and
renames it over the target in one step, and :func:`deferred` holds a signal that arrives while a
command writes its set of files until the set is complete, so an existing file is either left as
it was or replaced by a complete one.

Worker processes ignore SIGINT (:func:`ignore_interrupts`, their initializer): Ctrl-C in a terminal
reaches the whole process group, and it is the main process that decides to stop them.
"""
from __future__ import annotations

import contextlib
import os
import signal
import sys
import tempfile
import threading
from pathlib import Path

HANDLED_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(KeyboardInterrupt):
    """The command was stopped by ``signal_number`` (SIGINT or SIGTERM). A KeyboardInterrupt, so
    that code catching ``Exception`` (a fleet that records one bushing's failure and goes on)
    lets it through, and library code that cleans up after Ctrl-C cleans up after SIGTERM too."""

    def __init__(self, signal_number: int):
        super().__init__(signal_number)
        self.signal_number = signal_number

    @property
    def exit_status(self) -> int:
        """128 + the signal's number: 130 for SIGINT, 143 for SIGTERM."""
        return 128 + self.signal_number


# Module state, for the one command a process runs (lists, to be changed in place):
_written: list[Path] = []       # files the command now running has written, in order
_command_running = [False]      # inside signals_raise
_pending: list[int] = []        # signals held by `deferred`, oldest first
_deferring_depth = [0]          # `deferred` blocks now open


def _raise_interrupted(signal_number, frame):
    if _deferring_depth[0]:
        _pending.append(signal_number)
        return
    # the second signal must not interrupt the clean-up the first one started
    for handled in HANDLED_SIGNALS:
        signal.signal(handled, signal.SIG_IGN)
    raise Interrupted(signal_number)


@contextlib.contextmanager
def signals_raise():
    """SIGINT and SIGTERM raise :class:`Interrupted` in this (the main) thread inside the block;
    the previous handlers are restored after it. The list of written files starts empty.
    Outside the main thread (where Python cannot install handlers) the block runs unchanged."""
    _written.clear()
    _pending.clear()
    _command_running[0] = True
    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = {handled: signal.signal(handled, _raise_interrupted) for handled in HANDLED_SIGNALS} \
        if in_main_thread else {}
    try:
        yield
    finally:
        _command_running[0] = False
        for handled, handler in previous.items():
            # the early Ctrl-C handler says "nothing written": after a command, Python's own
            signal.signal(handled, signal.default_int_handler if handler is _exit_on_ctrl_c else handler)


@contextlib.contextmanager
def deferred():
    """Under :func:`signals_raise`, a signal that arrives inside the block is raised as
    :class:`Interrupted` when the block ends (normally or not), not inside it: a set of files is
    written completely. (Elsewhere Python's own handler raises KeyboardInterrupt where it is.)"""
    _deferring_depth[0] += 1
    try:
        yield
    finally:
        _deferring_depth[0] -= 1
        if not _deferring_depth[0] and _pending:
            _raise_interrupted(_pending.pop(0), None)


def record_written(*paths) -> None:
    """Note files a command has written, for the line printed if it is interrupted later (only
    while a command runs under :func:`signals_raise`: a library user's process keeps no list)."""
    if _command_running[0]:
        # a file written again (compare's table as each model is settled) is named once
        _written.extend(path for path in dict.fromkeys(Path(p) for p in paths if p is not None) if path not in _written)


def interrupted_message() -> str:
    """The one line printed when a command is interrupted: what it has written, if anything."""
    if not _written:
        return "interrupted: nothing written"
    names = ", ".join(str(path) for path in _written[:5]) + (f" and {len(_written) - 5} more" if len(_written) > 5
                                                              else "")
    return f"interrupted: wrote {names}; nothing else written"


@contextlib.contextmanager
def atomic_path(path: str | Path):
    """A temporary path beside ``path`` (same directory, same suffix, which some writers read the
    format from) to write to; when the block ends normally it is renamed to ``path`` in one step
    (``os.replace``), otherwise removed: ``path`` is never a partly written file."""
    path = Path(path)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=f".partial{path.suffix}")
    os.close(handle)
    temporary = Path(temporary)
    try:
        yield temporary
        if path.exists():
            # keep the permissions of the file replaced (mkstemp makes it 0600)
            os.chmod(temporary, path.stat().st_mode & 0o7777)
        else:
            os.chmod(temporary, 0o666 & ~_umask())
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


@contextlib.contextmanager
def writing(path: str | Path):
    """Write one output file whole or not at all: yields the temporary path to write to
    (:func:`atomic_path`), holds a signal until the file is in place (:func:`deferred`), and
    records the file as written (:func:`record_written`)."""
    path = Path(path)
    with deferred():
        with atomic_path(path) as temporary:
            yield temporary
        record_written(path)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def interrupts_held():
    """SIGINT is blocked in this thread inside the block and delivered when it ends (never lost).
    Worker processes started inside the block start with it blocked (a process inherits the
    mask), so a Ctrl-C while a worker imports its modules, before :func:`ignore_interrupts`
    runs, does not end it with a traceback. Without ``pthread_sigmask`` (Windows), nothing."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


COMMAND_NAMES = ("bushing-identify",)
"""The console script's name (``python -m identification`` is told by the interpreter's arguments)."""


def started_as_command() -> bool:
    """Whether this process is the command line (``python -m identification ...`` or
    ``bushing-identify ...``), not a program that imports the package: while Python imports the
    package, before ``cli.main`` runs, only the interpreter's own arguments tell."""
    arguments = list(getattr(sys, "orig_argv", ()))
    if "-m" in arguments:
        return arguments[arguments.index("-m") + 1:arguments.index("-m") + 2] == ["identification"]
    return bool(sys.argv) and Path(sys.argv[0]).name.startswith(COMMAND_NAMES)


def _exit_on_ctrl_c(signal_number, frame):
    sys.stderr.write("interrupted: nothing written\n")
    sys.stderr.flush()
    os._exit(128 + signal_number)   # during imports: nothing written, no worker started


def exit_quietly_on_early_ctrl_c() -> None:
    """In the command line only (:func:`started_as_command`), from the first line of the
    package's import until ``cli.main`` installs :func:`signals_raise`'s handlers: Ctrl-C ends the
    process with the one line and exit status 130 instead of a traceback from the middle of an
    import. (SIGTERM keeps its default then: the process ends at once, as a shell's 143, with no
    file written and no worker started.)"""
    if started_as_command() and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _exit_on_ctrl_c)


def ignore_interrupts() -> None:
    """A worker process's initializer: SIGINT ignored (the main process ends the workers), and
    unblocked (:func:`interrupts_held`), so that one sent while it was blocked is dropped."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
