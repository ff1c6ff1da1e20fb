#!/usr/bin/env bash
# Run the test suite (sets the machine up first when .venv is missing); arguments go to pytest.
# -n auto: one pytest-xdist worker per core (the NuSMV agreement groups are most of the time).
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO_ROOT"
if [ ! -x .venv/bin/pytest ]; then
    bash scripts/setup.sh
fi
# the web page's browser tests (tests/web) drive Debian's chromium; install it when missing
if [ -z "${FSMBT_SKIP_BROWSER:-}" ] && [ ! -x "${FSMBT_CHROMIUM:-/usr/bin/chromium}" ]; then
    bash scripts/install_browser.sh
fi
exec .venv/bin/pytest -n auto "$@"
