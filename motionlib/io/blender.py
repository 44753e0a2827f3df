"""A long-lived Blender process that reads and writes FBX (and glTF) for motionlib.

Blender (``bpy``, GPL) is never imported into a motionlib process: it runs as a child process
(``_blender_fbx.py`` under an interpreter that has ``bpy``), started on first use and kept for the
next file, so Blender's start-up (a second or more) is paid once per process, not per file.

The interpreter is, in order: ``$MOTIONLIB_BLENDER_PYTHON``; the ``.venv-bpy`` beside the source
tree (``make`` creates it: ``bpy`` pins numpy<2 while Cutroom pins numpy 2); the running
interpreter if it can import ``bpy``.

A file that crashes Blender, or keeps it busy past the time limit, costs that process only: the
caller gets a :class:`~motionlib.errors.CaptureError` naming the file and what happened, and the
next request starts a fresh Blender. A Blender that dies during a request (a crash, or a kill
from outside it: the kernel's out-of-memory killer, an operator) is tried once more in a fresh
process first (``retry_deaths``), so one outside kill does not fail a good file; a file that
kills Blender again fails (a hang is not retried: it would hang as long again).
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from motionlib.errors import CaptureError

HELPER = Path(__file__).with_name("_blender_fbx.py")
# Seconds one request may take before Blender is taken to hang and is killed.
DEFAULT_TIMEOUT = float(os.environ.get("MOTIONLIB_BLENDER_TIMEOUT") or 300)
START_TIMEOUT = 120.0


class BlenderUnavailable(CaptureError):
    """No interpreter with Blender (``bpy``) was found; the message says how to install one."""


class BlenderDied(CaptureError):
    """Blender ended during a request. ``permanent`` is False when it was killed from outside
    (SIGKILL: the out-of-memory killer, an operator), which trying again later may outlive."""

    def __init__(self, message, *, path=None, signal_name=None):
        super().__init__(message, path=path)
        self.signal_name = signal_name
        self.permanent = signal_name != "SIGKILL"


def blender_python() -> str:
    """Path of an interpreter that can import ``bpy``; BlenderUnavailable if there is none."""
    configured = os.environ.get("MOTIONLIB_BLENDER_PYTHON")
    if configured:
        if not Path(configured).is_file():
            raise BlenderUnavailable(f"MOTIONLIB_BLENDER_PYTHON={configured}: no such file")
        return configured
    beside = Path(__file__).resolve().parents[2] / ".venv-bpy" / "bin" / "python"
    if beside.is_file():
        return str(beside)
    if importlib.util.find_spec("bpy") is not None:
        return sys.executable
    raise BlenderUnavailable(
        "reading FBX needs Blender as a Python module (bpy 4.5) and none is installed: run "
        "`make bpy` (creates .venv-bpy) or set MOTIONLIB_BLENDER_PYTHON to a Python with bpy")


class Blender:
    """One Blender child process serving requests in order (one at a time)."""

    def __init__(self, python: str | None = None, retry_deaths: int = 1):
        self.python = python
        self.retry_deaths = retry_deaths
        self.proc = None
        self._reply = None
        self._log = None
        self._lock = threading.Lock()

    @property
    def pid(self) -> int | None:
        return self.proc.pid if self.alive() else None

    def alive(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    def start(self) -> None:
        """Start Blender and wait until it has loaded (a no-op when already running)."""
        with self._lock:
            self._ensure_started()

    def _ensure_started(self) -> None:
        if self.alive():
            return
        self.stop()
        python = self.python or blender_python()
        read_end, write_end = os.pipe()
        self._log = tempfile.TemporaryFile()
        self.proc = subprocess.Popen(
            # -I: the script's folder (motionlib/io, with its numbers.py) stays off sys.path.
            [python, "-I", str(HELPER), "--reply-fd", str(write_end)], stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL, stderr=self._log, pass_fds=(write_end,),
            start_new_session=True, text=True)
        os.close(write_end)
        self._reply = os.fdopen(read_end, "rb")
        self._exchange({"op": "ping"}, START_TIMEOUT, "starting Blender", None)

    def request(self, message: dict, *, path, what: str, timeout: float | None = None) -> dict:
        """Send one request; its reply (``ok`` true), or CaptureError naming ``path``.

        Parameters
        ----------
        message : dict
            The request (see ``_blender_fbx.py``).
        path : str
            The file concerned, for error messages.
        what : str
            What is being done ("reading", "writing"), for error messages.
        timeout : float, optional
            Seconds before Blender is taken to hang and killed (default
            ``$MOTIONLIB_BLENDER_TIMEOUT`` or 300).
        """
        timeout = DEFAULT_TIMEOUT if timeout is None else timeout
        with self._lock:
            for attempt in range(self.retry_deaths + 1):
                try:
                    self._ensure_started()
                    reply = self._exchange(message, timeout, what, path)
                    break
                except BlenderUnavailable as exc:
                    raise BlenderUnavailable(exc.reason, path=path) from None
                except BlenderDied as exc:  # while starting, or while doing the request
                    if attempt < self.retry_deaths:
                        continue
                    tried = f" (it was tried {attempt + 1} times, each in a fresh Blender)"
                    raise BlenderDied(exc.reason + (tried if attempt else ""), path=path,
                                      signal_name=exc.signal_name) from None
        if not reply.get("ok"):
            raise CaptureError(scrub(reply.get("error") or "Blender failed", path), path=path)
        return reply

    def _exchange(self, message, timeout, what, path):
        # Blender's log holds every file this process read (other projects' too): a death
        # is told with what it said during this request only.
        logged = os.fstat(self._log.fileno()).st_size if self._log is not None else 0
        try:
            self.proc.stdin.write(json.dumps(message) + "\n")
            self.proc.stdin.flush()
        except (BrokenPipeError, OSError):
            pass  # reported below as the process having stopped
        deadline = time.monotonic() + timeout
        line = b""
        while not line.endswith(b"\n"):
            left = deadline - time.monotonic()
            ready, _, _ = select.select([self._reply], [], [], max(left, 0))
            if not ready:
                self.kill()
                raise CaptureError(
                    f"Blender did not finish {what} within {timeout:g} s and was stopped; the "
                    "file may be damaged or far larger than a take (the limit is "
                    "MOTIONLIB_BLENDER_TIMEOUT)", path=path)
            chunk = os.read(self._reply.fileno(), 1 << 16)
            if not chunk:
                told, signal_name = self._death(what, logged)
                raise BlenderDied(scrub(told, path), path=path, signal_name=signal_name)
            line += chunk
        return json.loads(line)

    def _death(self, what, logged=0):
        try:
            code = self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.kill()
            code = self.proc.wait()
        tail = self.log_tail(since=logged)
        signal_name = signal.Signals(-code).name if code < 0 else None
        how = f"was killed by signal {signal_name}" if signal_name else f"exited with code {code}"
        self.stop()
        return (f"Blender {how} while {what}; the file may be damaged (Blender's last words: "
                f"{tail or 'none'})"), signal_name

    def log_tail(self, lines=3, since=0) -> str:
        """The last ``lines`` lines Blender logged after byte ``since`` of its log."""
        if self._log is None:
            return ""
        self._log.seek(since)
        text = self._log.read().decode("utf-8", "replace").strip().splitlines()
        return " | ".join(line.strip() for line in text[-lines:])

    def kill(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            self.proc.wait()
        self.stop()

    def stop(self) -> None:
        """End the child (closing its stdin ends its request loop) and forget it."""
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.stdin.close()
                try:
                    self.proc.wait(10)
                except subprocess.TimeoutExpired:
                    os.killpg(self.proc.pid, signal.SIGKILL)
                    self.proc.wait()
            elif self.proc.stdin:
                self.proc.stdin.close()
        for handle in (self._reply, self._log):
            if handle is not None:
                handle.close()
        self.proc = self._reply = self._log = None


# Text in quotes that holds a slash, and any other run of characters with one: paths.
_QUOTED_PATH = re.compile(r"""(['"])[^'"\n]*/[^'"\n]*\1""")
_PATH = re.compile(r"""[^\s'"|,;()\[\]<>]*/[^\s'"|,;()\[\]<>]*""")


def scrub(text: str, path=None) -> str:
    """Blender's ``text`` with ``path`` (the file asked about) shown by its name and every
    other path replaced by ``<path>``.

    What Blender says goes to whoever uploaded the file: it must not show where the service
    keeps files, nor another upload it read before (``captures/2/.../SECRET.fbx``), nor its
    own installation (``.venv-bpy/.../bpy/ops.py``).
    """
    if path is not None:
        for form in sorted({os.fspath(path), os.path.abspath(path)}, key=len, reverse=True):
            text = text.replace(form, os.path.basename(form))
    text = _QUOTED_PATH.sub(lambda m: f"{m.group(1)}<path>{m.group(1)}", text)
    return _PATH.sub("<path>", text)


_shared = None


def shared() -> Blender:
    """This process's Blender, started on first use and kept for the next file."""
    global _shared
    if _shared is None:
        _shared = Blender()
    return _shared
