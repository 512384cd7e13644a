"""The ``ballpit`` command's entry point: it imports almost nothing, so Ctrl+C is its own at once.

``main`` routes SIGINT, SIGTERM and SIGHUP to a handler first, then imports the commands (``commands``:
the parser, the physics, the scene reader), so a stop signal while they import exits 130, 143 or 129
with one line, never a traceback. Only Python's own start-up, before this module runs, is not covered.
Output that cannot be written ends the run the same way: a closed pipe (``| head``) quietly with 141, a
closed or full stdout with one line and status 1.
"""

from __future__ import annotations

import os
import signal
import sys

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a shell reports for a tool cut off by `| head`


class Terminated(BaseException):
    """SIGTERM or SIGHUP, raised in the main thread so that every cleanup runs (like KeyboardInterrupt)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


_STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")
_stopped_by: list[int] = []  # the stop signal that came, once one has


def _on_stop_signal(signum: int, frame: object) -> None:
    """The first stop signal unwinds the run; any later one is ignored, so the cleanup finishes."""
    for name in _STOP_SIGNALS:
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_IGN)
    _stopped_by.append(signum)
    raise _stop_exception(signum)


def _stop_exception(signum: int) -> BaseException:
    """What a stop signal unwinds the run with: KeyboardInterrupt for Ctrl+C, else Terminated."""
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated(signum)


def raise_if_stopped() -> None:
    """Raise the stop signal's exception again if one came and the run goes on.

    The handler raises it in whatever Python code the main thread runs when the signal is handled. If
    that is code whose exceptions Python ignores (a weakref callback such as importlib's module-lock
    one, a finaliser: "Exception ignored in ..."), the stop is lost, and the later signals are ignored
    by then, so a long run would go on to its end. The stepping loops call this once a step."""
    if _stopped_by:
        raise _stop_exception(_stopped_by[0])


def _install_stop_handlers() -> dict[int, object]:
    """Route SIGINT, SIGTERM and SIGHUP to _on_stop_signal; returns the handlers they had."""
    previous: dict[int, object] = {}
    for name in _STOP_SIGNALS:
        signum = getattr(signal, name, None)
        if signum is None or signal.getsignal(signum) == signal.SIG_IGN:  # e.g. nohup: keep ignoring
            continue
        try:
            previous[signum] = signal.signal(signum, _on_stop_signal)
        except ValueError:  # not the main thread: leave signals alone
            break
    return previous


class StdoutFailed(Exception):
    """Writing to stdout failed (closed, or a full disk): ``reason`` says why."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


class _Stdout:
    """sys.stdout while a command runs: writes go through, and a failure to write becomes StdoutFailed
    (BrokenPipeError stays itself: the reader left), told apart from an error of the command's own."""

    def __init__(self, stream: object | None) -> None:
        self._stream = stream

    def __getattr__(self, name: str) -> object:
        return getattr(self._stream, name)

    def _call(self, method: str, *args: object) -> object:
        if self._stream is None:  # started with stdout closed (`ballpit scenes >&-`)
            raise StdoutFailed("it is closed")
        try:
            return getattr(self._stream, method)(*args)
        except BrokenPipeError:
            raise
        except (OSError, ValueError) as e:  # ValueError: the stream was closed under us
            raise StdoutFailed(getattr(e, "strerror", None) or str(e)) from None

    def write(self, text: str) -> object:
        return self._call("write", text)

    def flush(self) -> object:
        return self._call("flush") if self._stream is not None else None

    def writelines(self, lines: object) -> object:
        return self._call("writelines", lines)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status.

    The stop handlers come first, so Ctrl+C or SIGTERM while the modules still import exits 130 or
    143 with one line, never a traceback. A closed pipe (``| head``) ends the run quietly (141); a closed
    or full stdout (``>&-``, ``> /dev/full``) with one line (1).
    """
    _stopped_by.clear()
    previous = _install_stop_handlers()
    stdout = sys.stdout
    _keep_descriptor_one_taken(stdout)
    sys.stdout = _Stdout(stdout)  # type: ignore[assignment]
    try:
        from .commands import run  # the parser, the physics and the scenes: once Ctrl+C is ours

        status = run(argv)
        sys.stdout.flush()  # here, not at exit, so a closed pipe or a full disk is caught below
        return status
    except KeyboardInterrupt:
        return _stopped(signal.SIGINT)
    except Terminated as e:
        return _stopped(e.signum)
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except StdoutFailed as e:
        print(f"ballpit: cannot write to stdout: {e.reason}", file=sys.stderr)
        _silence_stdout()
        return EXIT_FAILED
    except Exception:
        # A library may wrap the KeyboardInterrupt raised inside its import (NumPy's C extension turns
        # it into an ImportError): after a stop signal, whatever unwound the run is that signal.
        if not _stopped_by:
            raise
        return _stopped(_stopped_by[0])
    finally:
        sys.stdout = stdout
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _stopped(signum: int) -> int:
    """Say which stop signal ended the run; its exit status (130 for Ctrl+C, 128 + the signal's number)."""
    if signum == signal.SIGINT:
        print("ballpit: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    print(f"ballpit: stopped by {signal.Signals(signum).name}", file=sys.stderr)
    return 128 + signum


def _keep_descriptor_one_taken(stdout: object | None) -> None:
    """With stdout closed, hold descriptor 1 on /dev/null: a file the run opens must not become stdout."""
    if stdout is not None:
        return
    try:
        os.fstat(1)
    except OSError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        if devnull != 1:
            os.dup2(devnull, 1)
            os.close(devnull)


def _silence_stdout() -> None:
    """Point stdout at /dev/null, so the interpreter's last flush of what is left finds no closed pipe
    or full disk."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout replaced by something without a descriptor
        pass


if __name__ == "__main__":
    sys.exit(main())
