#!/usr/bin/env bash
# Build BehaviorTree.CPP 4.8.2 once per machine, then the fsmbt LEBT driver against it.
#
# Where the sources come from: the behaviortreepy 0.1.4 sdist on PyPI ships the full
# BehaviorTree.CPP 4.8.2 tree in its folder BehaviorTree.CPP/ (the same engine the Python tests
# run through behaviortreepy). The library is configured without its tests, examples, command-line
# tools and ZeroMQ/Groot2 publisher (none is needed to load and tick a tree), with its SQLite
# logger (the driver's --db3 log, docs/conform.md; needs SQLite's headers: Debian libsqlite3-dev,
# installed by scripts/setup.sh) and installed, as a shared library, into a cache OUTSIDE the
# checkout, keyed by version and build options (shared: the static build does not install its
# vendored tinyxml2, so nothing could link against it):
#
#     ${FSMBT_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/fsmbt}/btcpp-4.8.2-sqlite/
#         include/ lib/ lib/cmake/behaviortree_cpp/   the installed library (CMake package)
#         bin/fsmbt_lebt_driver                       the driver (src/fsmbt/runtime/cpp/driver)
#         bin/fsmbt_lebt_driver.sources               sha256 of the sources it was built from
#         build_times.txt                             seconds the last builds took
#
# A second run skips the library when its CMake package is installed, and the driver when the
# recorded hash matches the header and driver sources of this checkout (so CI's clean checkout
# reuses the machine's cache). Both builds are timed. Builds run under `nice -n 10` with JOBS
# parallel jobs (default 2).
#
# Without cmake or a C++17 compiler the script prints ONE line saying what is missing and exits
# 2; nothing else in fsmbt depends on this build (the C++ differential test is skipped, `fsmbt
# doctor` reports the runtime as not built).
#
# Environment:
#   FSMBT_CACHE   cache root (default ${XDG_CACHE_HOME:-$HOME/.cache}/fsmbt)
#   PYTHON        python used for `pip download` (default <checkout>/.venv/bin/python or python3)
#   JOBS          parallel build jobs (default 2)
#   FORCE=1       rebuild the library and the driver
#   CXX           C++ compiler (default g++, else c++, else clang++)
set -euo pipefail

BTCPP_VERSION="4.8.2"
BTPY_VERSION="0.1.4"
# the fsmbt package this script ships in; the checkout, when run from one (scripts/)
PKG_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CHECKOUT="${FSMBT_CHECKOUT:-}"
CACHE_ROOT="${FSMBT_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/fsmbt}"
# the cache folder's key: the version and the build options that change what is installed (the
# SQLite logger); must equal fsmbt.cache.BTCPP_BUILD
BTCPP_BUILD="$BTCPP_VERSION-sqlite"
PREFIX="$CACHE_ROOT/btcpp-$BTCPP_BUILD"
CPP_DIR="$PKG_DIR/runtime/cpp"
DRIVER_SRC="$CPP_DIR/driver/fsmbt_lebt_driver.cpp"
HEADER="$CPP_DIR/include/fsmbt/lebt.hpp"
DRIVER="$PREFIX/bin/fsmbt_lebt_driver"
JOBS="${JOBS:-2}"

say() { printf '[build_btcpp] %s\n' "$*"; }
die() { printf '[build_btcpp] ERROR: %s\n' "$*" >&2; exit 1; }

# --- tools: one line when something is missing ---------------------------------------------------
if [ -z "${CXX:-}" ]; then
    for candidate in g++ c++ clang++; do
        if command -v "$candidate" >/dev/null 2>&1; then CXX="$(command -v "$candidate")"; break; fi
    done
fi
missing=()
command -v cmake >/dev/null 2>&1 || missing+=("cmake")
{ [ -n "${CXX:-}" ] && command -v "$CXX" >/dev/null 2>&1; } || missing+=("a C++17 compiler (g++ or clang++)")
command -v make >/dev/null 2>&1 || command -v ninja >/dev/null 2>&1 || missing+=("make or ninja")
if [ ${#missing[@]} -gt 0 ]; then
    printf '[build_btcpp] cannot build the C++ runtime: missing %s (Debian: apt-get install cmake g++ make)\n' \
        "$(IFS=','; echo "${missing[*]}" | sed 's/,/, /g')" >&2
    exit 2
fi
export CXX
GENERATOR=()
command -v ninja >/dev/null 2>&1 && GENERATOR=(-G Ninja)

if [ -z "${PYTHON:-}" ]; then
    if [ -n "$CHECKOUT" ] && [ -x "$CHECKOUT/.venv/bin/python" ]; then PYTHON="$CHECKOUT/.venv/bin/python"; else PYTHON="python3"; fi
fi

WORK="$(mktemp -d "${TMPDIR:-/tmp}/fsmbt-btcpp-build.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT
LOG="$WORK/build.log"
run_logged() {  # run a step quietly; on failure show the end of its log
    local what="$1"; shift
    say "$what"
    if ! "$@" >>"$LOG" 2>&1; then
        tail -n 40 "$LOG" >&2
        die "$what failed"
    fi
}
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }

# --- 1. the library ----------------------------------------------------------------------------
PACKAGE_CONFIG="$PREFIX/lib/cmake/behaviortree_cpp/behaviortree_cppConfig.cmake"
if [ "${FORCE:-0}" != "1" ] && [ -f "$PACKAGE_CONFIG" ] && [ -f "$PREFIX/lib/libbehaviortree_cpp.so" ]; then
    say "BehaviorTree.CPP $BTCPP_VERSION already built: $PREFIX"
else
    T0="$(now)"
    run_logged "pip download behaviortreepy==$BTPY_VERSION (sdist with BehaviorTree.CPP $BTCPP_VERSION)" \
        "$PYTHON" -m pip download --disable-pip-version-check --no-binary :all: --no-deps \
        "behaviortreepy==$BTPY_VERSION" -d "$WORK/sdist"
    SDIST="$(ls "$WORK"/sdist/behaviortreepy-*.tar.gz 2>/dev/null | head -n1)"
    [ -n "$SDIST" ] || die "pip did not produce a behaviortreepy sdist"
    run_logged "unpack BehaviorTree.CPP/ from $(basename "$SDIST")" \
        tar -xzf "$SDIST" -C "$WORK" "behaviortreepy-$BTPY_VERSION/BehaviorTree.CPP"
    SRC="$WORK/behaviortreepy-$BTPY_VERSION/BehaviorTree.CPP"
    grep -q "VERSION $BTCPP_VERSION" "$SRC/CMakeLists.txt" \
        || die "the sdist's BehaviorTree.CPP is not version $BTCPP_VERSION"
    rm -rf "$PREFIX"
    run_logged "configure BehaviorTree.CPP (shared, SQLite logger; no tests, examples, tools, Groot2/ZeroMQ)" \
        cmake -S "$SRC" -B "$WORK/build" "${GENERATOR[@]}" \
        -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PREFIX" \
        -DCMAKE_CXX_COMPILER="$CXX" -DCMAKE_POSITION_INDEPENDENT_CODE=ON \
        -DBTCPP_SHARED_LIBS=ON -DBTCPP_BUILD_TOOLS=OFF -DBTCPP_EXAMPLES=OFF -DBUILD_TESTING=OFF \
        -DBTCPP_GROOT_INTERFACE=OFF -DBTCPP_SQLITE_LOGGING=ON
    run_logged "build BehaviorTree.CPP (nice -n 10, $JOBS jobs)" \
        nice -n 10 cmake --build "$WORK/build" --parallel "$JOBS"
    run_logged "install into $PREFIX" cmake --install "$WORK/build"
    [ -f "$PACKAGE_CONFIG" ] || die "install produced no CMake package at $PACKAGE_CONFIG"
    T1="$(now)"
    echo "library_seconds=$(elapsed "$T0" "$T1")" >"$PREFIX/build_times.txt"
    say "library built in $(elapsed "$T0" "$T1") s: $PREFIX"
fi

# --- 2. the driver -----------------------------------------------------------------------------
[ -f "$DRIVER_SRC" ] && [ -f "$HEADER" ] || die "driver sources not found under $CPP_DIR"
WANT="$(cat "$HEADER" "$DRIVER_SRC" | sha256sum | cut -d' ' -f1)"
STAMP="$DRIVER.sources"
if [ "${FORCE:-0}" != "1" ] && [ -x "$DRIVER" ] && [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$WANT" ]; then
    say "driver already built from these sources: $DRIVER"
else
    T0="$(now)"
    mkdir -p "$PREFIX/bin"
    # the driver's --db3 reads the SQLite log back (it waits until every transition is stored)
    SQLITE_LIB=()
    [ -f "$PREFIX/include/behaviortree_cpp/loggers/bt_sqlite_logger.h" ] && SQLITE_LIB=(-lsqlite3)
    run_logged "compile the driver ($(basename "$DRIVER_SRC") + fsmbt/lebt.hpp)" \
        nice -n 10 "$CXX" -std=c++17 -O2 -Wall -Wextra -o "$DRIVER.tmp" "$DRIVER_SRC" \
        -I"$CPP_DIR/include" -I"$PREFIX/include" -L"$PREFIX/lib" -Wl,-rpath,"$PREFIX/lib" -lbehaviortree_cpp "${SQLITE_LIB[@]}" -lpthread -ldl
    mv "$DRIVER.tmp" "$DRIVER"
    echo "$WANT" >"$STAMP"
    T1="$(now)"
    { grep -v '^driver_seconds=' "$PREFIX/build_times.txt" 2>/dev/null || true
      echo "driver_seconds=$(elapsed "$T0" "$T1")"; } >"$WORK/times" && mv "$WORK/times" "$PREFIX/build_times.txt"
    say "driver built in $(elapsed "$T0" "$T1") s: $DRIVER"
fi
"$DRIVER" --version | sed 's/^/[build_btcpp] /'
