"""The evaluation's one door to the batch runner (issue 14, ``fsmbt.batch``).

Every other module of ``fsmbt.evaluate`` imports ``Job``, ``JobResult``, ``ResultStore`` and
``run_jobs`` from here, never from ``fsmbt.batch``: when the batch runner is installed it is
used (local processes or Ray), otherwise the private stand-in ``_batch_fallback`` with the same
contract (local processes only). ``BATCH_SOURCE`` says which one ran; the report prints it.
"""

from __future__ import annotations

try:
    from fsmbt.batch import (  # type: ignore[import-untyped, unused-ignore]
        Job,
        JobResult,
        ResultStore,
        run_jobs,
    )

    BATCH_SOURCE = "fsmbt.batch"
except ImportError:  # the batch runner is not merged yet
    from fsmbt.evaluate._batch_fallback import (  # type: ignore[assignment]
        Job,
        JobResult,
        ResultStore,
        run_jobs,
    )

    BATCH_SOURCE = "fsmbt.evaluate._batch_fallback"

__all__ = ["BATCH_SOURCE", "Job", "JobResult", "ResultStore", "run_jobs"]
