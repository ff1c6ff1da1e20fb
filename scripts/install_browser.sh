#!/usr/bin/env bash
# Install the browser the web page's end-to-end tests drive (tests/web, docs/web.md): Debian's
# `chromium` package, driven by Playwright for Python (pinned in pyproject.toml) through
# executable_path. Never `playwright install`: no browser is downloaded from anywhere but apt.
# Safe to run again: does nothing when the browser is there. FSMBT_CHROMIUM names another binary.
set -euo pipefail
BROWSER="${FSMBT_CHROMIUM:-/usr/bin/chromium}"
if [ -x "$BROWSER" ]; then
    exit 0
fi
command -v apt-get >/dev/null 2>&1 || {
    echo "[install_browser] apt-get not found: install chromium by hand (or set FSMBT_CHROMIUM)" >&2
    exit 1
}
SUDO=""
if [ "$(id -u)" != "0" ]; then
    command -v sudo >/dev/null 2>&1 || { echo "[install_browser] need root or sudo" >&2; exit 1; }
    SUDO="sudo"
fi
echo "[install_browser] installing Debian's chromium (for tests/web)"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null
[ -x "$BROWSER" ] || { echo "[install_browser] chromium is not at $BROWSER after install" >&2; exit 1; }
