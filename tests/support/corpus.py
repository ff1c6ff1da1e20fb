"""Where the shared corpus (real files written by other people, read-only) is: ``FSMBT_CORPUS``,
else ``<repo>/../shared/corpus`` exactly as CI spells it - not resolved, so the tests see the
path a user gives, with its ``..``, and any code that compares a resolved path with the given
one fails here rather than only on CI."""

from __future__ import annotations

import os
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("FSMBT_CORPUS", REPO / ".." / "shared" / "corpus"))
