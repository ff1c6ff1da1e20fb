"""Seeded samples of the long suites, so the whole test command fits CI's time budget.

A suite that enumerates hundreds of pairs or files (the NuSMV agreement groups, the corpus
sweeps) checks a seeded sample of them on every run and all of them on request:

- ``FSMBT_FULL_SUITES=1``: every item (what a release check runs);
- ``FSMBT_TEST_SEED=<n>``: another sample (the default seed is fixed, so CI is reproducible;
  a failure prints the label and the seed that drew it).

The draw depends only on the seed, the suite's label and the items' order, never on the
machine: two runs with one seed check the same items.
"""

from __future__ import annotations

import os
import random
from collections.abc import Iterable, Sequence
from typing import TypeVar

T = TypeVar("T")

#: The default seed: fixed, so a red CI run is reproduced by running the same command again.
DEFAULT_SEED = 20261204


def seed() -> int:
    """The seed of this run (``FSMBT_TEST_SEED``, else ``DEFAULT_SEED``)."""
    return int(os.environ.get("FSMBT_TEST_SEED", str(DEFAULT_SEED)))


def full() -> bool:
    """Whether every item of every long suite is checked (``FSMBT_FULL_SUITES=1``)."""
    return os.environ.get("FSMBT_FULL_SUITES", "") == "1"


def sample(items: Iterable[T], size: int, label: str) -> list[T]:
    """``size`` of ``items`` drawn with the run's seed (their order kept), or all of them when
    there are no more than ``size`` or ``FSMBT_FULL_SUITES=1``. Prints what was drawn."""
    pool: Sequence[T] = list(items)
    if full() or len(pool) <= size:
        return list(pool)
    rng = random.Random(f"{seed()}:{label}")
    chosen = sorted(rng.sample(range(len(pool)), size))
    print(
        f"\n{label}: {size} of {len(pool)} sampled (seed {seed()}; FSMBT_FULL_SUITES=1 "
        "checks all, FSMBT_TEST_SEED=<n> draws another sample)"
    )
    return [pool[i] for i in chosen]
