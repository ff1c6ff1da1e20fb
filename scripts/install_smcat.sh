#!/usr/bin/env bash
# Install state-machine-cat (npm, pinned in tools/smcat/package.json and its package-lock.json)
# into tools/smcat/node_modules: tests/formats/smcat check that every .smcat file fsmbt writes is
# read by state-machine-cat itself (docs/formats/smcat.md). Safe to run again (npm ci is skipped
# when the installed lock matches). Skipped, with one line, when npm is missing or
# FSMBT_SKIP_SMCAT=1; the smcat tests then skip that one check and say why.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DIR="$ROOT/tools/smcat"
if [ "${FSMBT_SKIP_SMCAT:-0}" = "1" ]; then
    echo "[setup] state-machine-cat: skipped (FSMBT_SKIP_SMCAT=1)"
    exit 0
fi
if ! command -v npm >/dev/null 2>&1; then
    echo "[setup] state-machine-cat: skipped (npm not found; install nodejs and npm to check written .smcat files)"
    exit 0
fi
WANT="$(sha256sum "$DIR/package-lock.json" | cut -d' ' -f1)"
STAMP="$DIR/node_modules/.fsmbt-installed"
if [ -x "$DIR/node_modules/.bin/smcat" ] && [ "$(cat "$STAMP" 2>/dev/null)" = "$WANT" ]; then
    echo "[setup] state-machine-cat: $("$DIR/node_modules/.bin/smcat" --version)"
    exit 0
fi
echo "[setup] state-machine-cat: npm ci in tools/smcat"
(cd "$DIR" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
echo "$WANT" >"$STAMP"
echo "[setup] state-machine-cat: $("$DIR/node_modules/.bin/smcat" --version)"
