#!/usr/bin/env bash
# Static checks, in CI order, stopping at the first failure: ruff lint, ruff format check, mypy
# (config in pyproject.toml: strict for model/, semantics/, verify/), the import-linter layer
# contracts, no import cycle between any two modules of fsmbt (function-level and TYPE_CHECKING
# imports counted) and no private name used across modules. Tools come from the venv:
# $FSMBT_VENV, else the checkout's .venv.
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
echo "== import cycles (every module of fsmbt; local and TYPE_CHECKING imports counted)"
"$VENV/bin/python" scripts/import_cycles.py --root src
echo "== private names across modules"
"$VENV/bin/python" scripts/private_access.py --root src
echo "all static checks passed"
