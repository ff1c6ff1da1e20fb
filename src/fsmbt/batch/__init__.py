"""``fsmbt batch``: many models at once, on local processes or on Ray, resumable, nothing lost.

A layer above ``fsmbt.api``: every job calls the library's pipeline (``convert_file``, or
``load_for_llm`` and ``convert_loaded`` for the LLM engines) and never redoes its work.

- ``make_jobs`` (``jobs``): files, folders and globs to ``Job`` values, outputs mirrored.
- ``run_job`` (``worker``): one job, every problem a row (``JobResult``, ``result``).
- ``ResultStore`` (``store``): the SQLite store, one row per job key, written by the driver.
- ``run_jobs`` (``driver``): skip what is done, run the rest on ``local`` (``local``) or
  ``ray`` (``ray_executor``), store each result as it arrives.

docs/batch.md states the rules: statuses, the store's schema, resume, Ray clusters, LLM limits.
"""

from fsmbt.batch.driver import run_jobs
from fsmbt.batch.jobs import Job, make_jobs
from fsmbt.batch.result import STATUSES, JobResult
from fsmbt.batch.store import STORE_NAME, ResultStore
from fsmbt.batch.worker import run_job

__all__ = [
    "Job",
    "JobResult",
    "ResultStore",
    "STATUSES",
    "STORE_NAME",
    "make_jobs",
    "run_job",
    "run_jobs",
]
