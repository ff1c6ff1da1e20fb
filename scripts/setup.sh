#!/usr/bin/env bash
# Set up fsmbt on a fresh Debian machine (run as root or with sudo); safe to run again.
#
#   1. Graphviz's `dot` (Debian package graphviz) when it is missing  - for `fsmbt render`; and
#      GoogleTest (Debian libgtest-dev) when missing - for the C++ files `fsmbt testgen` writes;
#      SQLite's headers (Debian libsqlite3-dev) when missing - BehaviorTree.CPP's SQLite logger
#   2. .venv with Python 3.11 (python3.11, or python3 when that is 3.11)
#   3. the project and its pinned dependencies: pip install -e '.[test]' (pins live in
#      pyproject.toml); skipped when pyproject.toml has not changed since the last install
#   4. NuSMV, built from source by scripts/build_nusmv.sh when that script is present
#   5. the C++ runtime: BehaviorTree.CPP 4.8.2 and the LEBT driver, built by scripts/build_btcpp.sh
#      into the machine's cache (once per machine); a machine without cmake/g++ gets one line
#      saying what is missing and the rest of the setup still succeeds
#   6. state-machine-cat from npm (pinned in tools/smcat) by scripts/install_smcat.sh; skipped
#      when npm is missing or FSMBT_SKIP_SMCAT=1
#
# Environment: PYTHON=/path/to/python3.11 picks the interpreter; FSMBT_SKIP_NUSMV=1 skips step 4;
# FSMBT_SKIP_BTCPP=1 skips step 5; FSMBT_CACHE moves the build cache of steps 4 and 5.
set -euo pipefail

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO_ROOT"
VENV="$REPO_ROOT/.venv"
STAMP="$VENV/.fsmbt-installed"
LOG="$(mktemp -t fsmbt-setup.XXXXXX.log)"
trap 'rm -f "$LOG"' EXIT

say() { printf '[setup] %s\n' "$*"; }
die() { printf '[setup] ERROR: %s\n' "$*" >&2; exit 1; }
# Run a noisy command with its output in the log; show the log's tail only when it fails.
quietly() {
    if ! "$@" >"$LOG" 2>&1; then
        tail -n 30 "$LOG" >&2
        die "failed: $*"
    fi
}

SUDO=""
APT_UPDATED=0
apt_install() {
    command -v apt-get >/dev/null 2>&1 || die "apt-get not found: install $* by hand, then run this again"
    if [ "$(id -u)" != "0" ]; then
        command -v sudo >/dev/null 2>&1 || die "need root or sudo to install $*"
        SUDO="sudo"
    fi
    if [ "$APT_UPDATED" = "0" ]; then
        say "apt-get update"
        quietly $SUDO apt-get update
        APT_UPDATED=1
    fi
    say "apt-get install $*"
    quietly $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "$@"
}

is_py311() { "$1" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' >/dev/null 2>&1; }

# -- 1. Graphviz --------------------------------------------------------------------------------
if command -v dot >/dev/null 2>&1; then
    say "Graphviz: $(command -v dot)"
else
    apt_install graphviz
fi

# GoogleTest: the C++ test files `fsmbt testgen` writes link it (docs/testgen.md)
if [ -f /usr/include/gtest/gtest.h ]; then
    say "GoogleTest: /usr/include/gtest"
else
    apt_install libgtest-dev
fi

# SQLite's headers: BehaviorTree.CPP is built with its SqliteLogger (the driver's --db3 log,
# docs/conform.md); cmake's find_package(SQLite3) needs them
if [ -f /usr/include/sqlite3.h ]; then
    say "SQLite headers: /usr/include/sqlite3.h"
else
    apt_install libsqlite3-dev
fi

# -- 2. Python 3.11 and the virtual environment -------------------------------------------------
if [ -x "$VENV/bin/python" ] && is_py311 "$VENV/bin/python" && [ -x "$VENV/bin/pip" ]; then
    say "virtual env: $VENV"
else
    PY="${PYTHON:-}"
    if [ -z "$PY" ]; then
        for candidate in python3.11 python3; do
            if command -v "$candidate" >/dev/null 2>&1 && is_py311 "$candidate"; then
                PY="$(command -v "$candidate")"
                break
            fi
        done
    fi
    if [ -z "$PY" ]; then
        apt_install python3.11 python3.11-venv
        PY="$(command -v python3.11)" || die "python3.11 is not available from apt"
    fi
    is_py311 "$PY" || die "$PY is not Python 3.11"
    # Debian splits venv/ensurepip into its own package.
    if ! "$PY" -c 'import ensurepip, venv' >/dev/null 2>&1; then
        apt_install python3.11-venv
    fi
    say "creating $VENV with $PY"
    rm -rf "$VENV"
    quietly "$PY" -m venv "$VENV"
fi

# -- 3. fsmbt and its pinned dependencies --------------------------------------------------------
WANT="$(sha256sum pyproject.toml | cut -d' ' -f1)"
if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$WANT" ] && [ -x "$VENV/bin/fsmbt" ]; then
    say "fsmbt already installed (pyproject.toml unchanged)"
else
    say "pip install -e '.[test]' (pinned dependencies; a few minutes on a fresh machine)"
    quietly "$VENV/bin/python" -m pip install --disable-pip-version-check -e '.[test]'
    echo "$WANT" >"$STAMP"
fi

# -- 4. NuSMV (second verification engine) -------------------------------------------------------
if [ "${FSMBT_SKIP_NUSMV:-0}" = "1" ]; then
    say "NuSMV: skipped (FSMBT_SKIP_NUSMV=1)"
elif [ -x scripts/build_nusmv.sh ]; then
    say "NuSMV: scripts/build_nusmv.sh"
    PYTHON="$VENV/bin/python" scripts/build_nusmv.sh
fi

# -- 5. the C++ runtime (BehaviorTree.CPP + LEBT driver) -----------------------------------------
if [ "${FSMBT_SKIP_BTCPP:-0}" = "1" ]; then
    say "C++ runtime: skipped (FSMBT_SKIP_BTCPP=1)"
elif [ -x scripts/build_btcpp.sh ]; then
    say "C++ runtime: scripts/build_btcpp.sh"
    status=0
    PYTHON="$VENV/bin/python" scripts/build_btcpp.sh || status=$?
    if [ "$status" = "2" ]; then
        say "C++ runtime: not built (see the line above); everything else works"
    elif [ "$status" != "0" ]; then
        die "scripts/build_btcpp.sh failed"
    fi
fi

# -- 6. state-machine-cat (npm, pinned): the tests check written .smcat files with it -----------
bash scripts/install_smcat.sh

say "ready: $VENV/bin/fsmbt"
