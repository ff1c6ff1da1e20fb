"""Progress on stderr for work that can take more than a second (``--quiet`` turns it off).

Why a spinner with the running step's name, not a bar: a conversion or a proof does not know
its own length in advance (the checker explores a state space of unknown size), so a bar would
lie; the name of the step that is running tells the user what is going on.

The display is shown only when stderr is a terminal (never in pipes, logs or CI) and not
``--quiet``; it is drawn by rich's ``Status`` on stderr, so stdout stays clean for a model or
JSON. ``StageProgress`` is handed to the library as its ``on_stage`` hook; each step's time
comes back in the ``Outcome``'s timings, which the command prints at the end
(``format_timings``).
"""

from __future__ import annotations

import sys
from types import TracebackType

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.status import Status

#: What each library step is called on screen.
STAGE_WORDS = {
    "read": "reading the model",
    "convert": "converting",
    "verify": "proving equivalence",
    "load": "loading the tree in BehaviorTree.CPP",
    "write": "writing the result",
}


class StageProgress:
    """An ``on_stage`` hook that shows the running step on stderr (a context manager)."""

    def __init__(self, *, quiet: bool = False, label: str = "") -> None:
        self.enabled = not quiet and sys.stderr.isatty()
        self.label = label
        self._status: Status | None = None
        self._console = Console(stderr=True) if self.enabled else None

    def __call__(self, stage: str) -> None:
        if self._status is None:
            return
        words = STAGE_WORDS.get(stage, stage)
        prefix = f"{self.label}: " if self.label else ""
        self._status.update(f"{prefix}{words} …")

    def __enter__(self) -> StageProgress:
        if self._console is not None:
            self._status = self._console.status("starting …", spinner="dots")
            self._status.start()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        if self._status is not None:
            self._status.stop()
            self._status = None


def format_timings(timings: dict[str, float]) -> str:
    """``read 0.01 s, convert 0.20 s, verify 1.52 s`` in the order the steps ran."""
    return ", ".join(f"{stage} {seconds:.2f} s" for stage, seconds in timings.items())


class MethodBars:
    """``fsmbt evaluate``'s per-method progress bars with ETA on stderr (a context manager).

    It is the ``on_progress(label, done, total)`` hook of ``fsmbt.evaluate.evaluate``: the first
    call for a label adds its bar (starting at what the results store already held), later
    calls move it. Drawn only when stderr is a terminal and not ``--quiet``.
    """

    def __init__(self, *, quiet: bool = False) -> None:
        self.enabled = not quiet and sys.stderr.isatty()
        self._bars: Progress | None = None
        self._tasks: dict[str, TaskID] = {}

    def __call__(self, label: str, done: int, total: int) -> None:
        if self._bars is None:
            return
        task = self._tasks.get(label)
        if task is None:
            self._tasks[label] = self._bars.add_task(label, total=total, completed=done)
        else:
            self._bars.update(task, completed=done, total=total)

    def __enter__(self) -> MethodBars:
        if self.enabled:
            self._bars = Progress(
                TextColumn("{task.description:>24}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
            )
            self._bars.start()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        if self._bars is not None:
            self._bars.stop()
            self._bars = None
