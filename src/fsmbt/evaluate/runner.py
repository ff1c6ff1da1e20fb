"""The evaluation's one door to the batch runner (``fsmbt.batch``).

Every other module of ``fsmbt.evaluate`` imports ``Job``, ``JobResult``, ``ResultStore`` and
``run_jobs`` from here, so the evaluation runs on exactly the runner ``fsmbt batch`` uses (local
processes or Ray, the SQLite store that resumes a killed run). ``BATCH_SOURCE`` names it in the
report.
"""

from __future__ import annotations

from fsmbt.batch import Job, JobResult, ResultStore, run_jobs

BATCH_SOURCE = "fsmbt.batch"

__all__ = ["BATCH_SOURCE", "Job", "JobResult", "ResultStore", "run_jobs"]
