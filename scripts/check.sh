#!/usr/bin/env bash
# Static checks, in CI order, stopping at the first failure: ruff lint, ruff format check, mypy
# (config in pyproject.toml: strict for model/, semantics/, verify/) and the import-linter layer
# contracts. Tools come from the venv: $FSMBT_VENV, else the checkout's .venv.
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO_ROOT"
VENV="${FSMBT_VENV:-$REPO_ROOT/.venv}"
if [ ! -x "$VENV/bin/ruff" ]; then
    echo "check.sh: no ruff in $VENV (run scripts/setup.sh, or set FSMBT_VENV)" >&2
    exit 2
fi
# the checkout's own sources, whatever fsmbt the venv has installed
export PYTHONPATH="$REPO_ROOT/src${PYTHONPATH:+:$PYTHONPATH}"
export MYPYPATH="$REPO_ROOT/src"

echo "== ruff check (lint: src tests benchmarks)"
"$VENV/bin/ruff" check src tests benchmarks fuzz
echo "== ruff format --check (src tests benchmarks)"
"$VENV/bin/ruff" format --check src tests benchmarks fuzz
echo "== mypy (package fsmbt)"
"$VENV/bin/mypy"
echo "== lint-imports (layer contracts)"
"$VENV/bin/lint-imports"
echo "all static checks passed"
