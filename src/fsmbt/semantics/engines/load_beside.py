"""A written result's load check, run beside its proof (docs/semantics.md §5, "Every written
tree loads"; docs/architecture.md).

Why: the load check of a large result costs as much as its proof or more (python-statemachine
takes 4-6 s of CPU to build and start a 15 000-state SCXML chart in the child, whose cyclic
collector is off - 12-16 s with it on, ``scxml_load.main`` - the per-node proof of that result
about 4 s), and the two are independent - both read the converted model, neither reads
the other's answer. Run side by side on the two cores a user has, ``convert`` waits for the
longer of the two instead of their sum.

Rule: ``start_load_check(text, fmt)`` starts the check and returns a ``PendingLoad``; the caller
proves the result, then takes ``result()`` (the same ``LoadCheck`` the check gives when run
alone), or ``cancel()``s it when the proof raised (a check nobody reads is stopped, its child
killed: no process is left behind).

- ``btcpp``: ``btcpp_load.check_loads`` on a thread of this process. Its C++ check is a child
  process, and waiting for a child releases the GIL, so it runs while the proof does.
- ``scxml``: a document of ``BESIDE_BYTES`` or more is checked by a child Python process
  (``python -m fsmbt.semantics.engines.scxml_load FILE``: the text in a temporary file, removed
  when the check ends; the answer as one JSON line), bounded by ``fsmbt.child_process`` (address space, CPU, death with its parent)
  and by ``load_max_seconds``; a smaller one is checked in this process when ``result()`` is
  called, as a child's start-up (about 0.2 s) would cost about as much as it saves (a
  300 kB document, a 600-node tree's HFSM, takes python-statemachine about 0.7 s). A child that cannot
  answer (killed, out of memory, no JSON) is a refusal that says so, never a silent pass; one
  that cannot start (no temporary file, no process) leaves the check to this process.

Costs: one thread, or one process start plus the engine's own O(document size) work.
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import Future, ThreadPoolExecutor

from fsmbt.child_process import bounded_child
from fsmbt.semantics.engines.btcpp_load import LoadCheck, check_loads
from fsmbt.semantics.engines.scxml_load import check_scxml_loads, engine_name

#: SCXML documents at least this long are checked in a child process beside the proof.
BESIDE_BYTES = 300_000
#: What the child Python runs (its arguments before the file's path).
CHILD_COMMAND: tuple[str, ...] = ("-m", "fsmbt.semantics.engines.scxml_load")
#: Wall seconds a child's load check may take before it is a refusal.
LOAD_MAX_SECONDS = 600.0
#: Address space of a child's load check, MiB.
LOAD_MAX_MEMORY_MB = 8192


class PendingLoad:
    """A load check under way (module docstring). ``result()`` waits for it; ``cancel()``
    stops it. Either may be called more than once."""

    def __init__(self, fmt: str, text: str) -> None:
        self._fmt = fmt
        self._text = text
        self._future: Future[LoadCheck] | None = None
        self._child: subprocess.Popen[str] | None = None
        self._file: str | None = None
        self._answer: LoadCheck | None = None
        self._done = False
        if fmt == "btcpp":
            pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="fsmbt-load")
            self._future = pool.submit(check_loads, text)
            pool.shutdown(wait=False)
        elif fmt == "scxml" and len(text) >= BESIDE_BYTES and engine_name() is not None:
            try:
                self._child = self._start_child(text)
            except OSError:  # no temporary file, no process: the check runs here, after
                self._forget_file()
                self._child = None

    def _start_child(self, text: str) -> subprocess.Popen[str]:
        handle, self._file = tempfile.mkstemp(prefix="fsmbt-load-", suffix=".scxml")
        with os.fdopen(handle, "w", encoding="utf-8") as out:
            out.write(text)
        return subprocess.Popen(
            [sys.executable, *CHILD_COMMAND, self._file],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            encoding="utf-8",
            errors="replace",
            preexec_fn=bounded_child(LOAD_MAX_MEMORY_MB, LOAD_MAX_SECONDS),
        )

    @property
    def in_child(self) -> bool:
        """Whether the check runs in a child process (a large SCXML document)."""
        return self._child is not None

    def result(self) -> LoadCheck | None:
        """The check's answer (``None``: no engine for this format is installed)."""
        if not self._done:
            try:
                self._answer = self._wait()
            finally:
                self._forget_file()
            self._done = True
        return self._answer

    def cancel(self) -> None:
        """Stop the check: its child is killed and reaped; a thread's C++ child ends with
        ``check_loads``'s own timeout (the thread is not waited for)."""
        if self._child is not None and self._child.poll() is None:
            self._child.kill()
            self._child.communicate()
        self._forget_file()
        self._done = True

    def _forget_file(self) -> None:
        if self._file is not None:
            with contextlib.suppress(OSError):
                os.unlink(self._file)
            self._file = None

    def _wait(self) -> LoadCheck | None:
        if self._future is not None:
            return self._future.result()
        if self._child is None:
            return check_scxml_loads(self._text) if self._fmt == "scxml" else None
        engine = engine_name() or "python-statemachine"
        try:
            out, err = self._child.communicate(timeout=LOAD_MAX_SECONDS)
        except subprocess.TimeoutExpired:
            self._child.kill()
            self._child.communicate()
            return LoadCheck(
                engine, False, f"the load did not finish within {LOAD_MAX_SECONDS:g} s"
            )
        lines = out.strip().splitlines()
        try:
            answer = json.loads(lines[-1]) if self._child.returncode == 0 and lines else None
        except json.JSONDecodeError:
            answer = None
        if not isinstance(answer, dict):
            why = " ".join(err.split())[-300:] or f"exit status {self._child.returncode}"
            return LoadCheck(engine, False, f"the load check's process gave no answer ({why})")
        return LoadCheck(**answer)


def start_load_check(text: str, fmt: str) -> PendingLoad:
    """Start the load check of ``text`` written as ``fmt`` (``btcpp`` or ``scxml``; any other
    format has no check: its ``result()`` is ``None``)."""
    return PendingLoad(fmt, text)
