#!/usr/bin/env bash
# CI step (issue 15): the evaluation's --quick subset end to end, then the tests that check the
# report's shape and the numbers that must hold (tests/evaluate). About 4 min on 2 shared cores
# (measured: 3 min 52 s under nice -n 10; the edit-distance searches are 2 s each with --quick).
# Report folder: $1, else a temporary folder (kept, its path printed).
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO_ROOT"
VENV="${FSMBT_VENV:-$REPO_ROOT/.venv}"
export PYTHONPATH="$REPO_ROOT/src${PYTHONPATH:+:$PYTHONPATH}"
OUT="${1:-$(mktemp -d)/evaluation}"
"$VENV/bin/python" -m fsmbt.cli evaluate --quick --nusmv 3 -o "$OUT" --quiet
test -s "$OUT/report.html" && test -s "$OUT/report.md"
"$VENV/bin/python" -m pytest -p no:xdist -q tests/evaluate
echo "evaluation report: $OUT/report.md"
