#!/usr/bin/env bash
# Build the NuSMV 2.5.4 model checker from the sources shipped in the pynusmv sdist on PyPI.
#
# Why from pynusmv: it is the only place on PyPI that carries the NuSMV-2.5.4 sources, and PyPI is
# reachable from every machine this project runs on. The build is cached once per machine, outside
# the checkout and keyed by version (so a clean CI checkout does not rebuild it): the binary lands
# in ${FSMBT_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/fsmbt}/nusmv-2.5.4/bin/NuSMV, and a second
# run returns at once when that binary exists and answers `-h`. A binary an older version of
# this script built in <repo>/.cache/nusmv is copied into the cache instead of rebuilding.
#
# Environment:
#   FSMBT_CACHE         cache root (default ${XDG_CACHE_HOME:-$HOME/.cache}/fsmbt)
#   FSMBT_NUSMV_PREFIX  install prefix (default <cache root>/nusmv-2.5.4)
#   PYTHON              python used for `pip download` (default <checkout>/.venv/bin/python or python3)
#   JOBS                parallel make jobs (default: nproc)
#   FORCE=1             rebuild even when a working binary exists
set -euo pipefail

PYNUSMV_VERSION="1.0rc8"
NUSMV_VERSION="2.5.4"
# the checkout, when run from one (scripts/build_nusmv.sh sets it)
CHECKOUT="${FSMBT_CHECKOUT:-}"
CACHE_ROOT="${FSMBT_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/fsmbt}"
PREFIX="${FSMBT_NUSMV_PREFIX:-$CACHE_ROOT/nusmv-$NUSMV_VERSION}"
LEGACY_BIN="${CHECKOUT:-/nonexistent}/.cache/nusmv/bin/NuSMV"
BIN="$PREFIX/bin/NuSMV"
JOBS="${JOBS:-$(nproc 2>/dev/null || echo 2)}"

say() { printf '[build_nusmv] %s\n' "$*"; }
die() { printf '[build_nusmv] ERROR: %s\n' "$*" >&2; exit 1; }

binary_works() {  # exists, runs, and is NuSMV (it lists its -dcx option under -h)
    local help
    [ -x "$1" ] || return 1
    help="$("$1" -h 2>&1 || true)"
    case "$help" in *"-dcx"*) return 0 ;; *) return 1 ;; esac
}

if [ "${FORCE:-0}" != "1" ] && binary_works "$BIN"; then
    say "NuSMV already built: $BIN"
    exit 0
fi
if [ "${FORCE:-0}" != "1" ] && binary_works "$LEGACY_BIN"; then
    mkdir -p "$PREFIX/bin"
    cp "$LEGACY_BIN" "$BIN.tmp"
    mv "$BIN.tmp" "$BIN"
    say "NuSMV copied from the old per-checkout cache $LEGACY_BIN: $BIN"
    exit 0
fi

if [ -z "${PYTHON:-}" ]; then
    if [ -n "$CHECKOUT" ] && [ -x "$CHECKOUT/.venv/bin/python" ]; then PYTHON="$CHECKOUT/.venv/bin/python"; else PYTHON="python3"; fi
fi

# --- build dependencies (Debian) ---------------------------------------------------------------
# The NuSMV tarball ships lex/yacc grammars, not generated parsers: flex and bison are required.
need_pkgs=()
for tool in gcc:gcc make:make flex:flex bison:bison patch:patch; do
    command -v "${tool%%:*}" >/dev/null 2>&1 || need_pkgs+=("${tool##*:}")
done
if [ ${#need_pkgs[@]} -gt 0 ]; then
    say "missing build tools: ${need_pkgs[*]}"
    if command -v apt-get >/dev/null 2>&1; then
        SUDO=""
        if [ "$(id -u)" != "0" ]; then
            command -v sudo >/dev/null 2>&1 || die "need root or sudo to apt-get install ${need_pkgs[*]}"
            SUDO="sudo"
        fi
        say "apt-get install ${need_pkgs[*]}"
        $SUDO apt-get update -qq || die "apt-get update failed"
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_pkgs[@]}" \
            || die "apt-get install ${need_pkgs[*]} failed"
    else
        die "install these tools first: ${need_pkgs[*]}"
    fi
fi

START=$(date +%s)
WORK="$(mktemp -d "${TMPDIR:-/tmp}/fsmbt-nusmv-build.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT
LOG="$WORK/build.log"
run_logged() {  # run a step quietly; on failure show the end of its log
    local what="$1"; shift
    say "$what"
    if ! "$@" >>"$LOG" 2>&1; then
        tail -n 40 "$LOG" >&2
        die "$what failed (full log was $LOG)"
    fi
}

# --- sources -----------------------------------------------------------------------------------
run_logged "pip download pynusmv==$PYNUSMV_VERSION (sdist)" \
    "$PYTHON" -m pip download --no-binary :all: --no-deps \
    "pynusmv==$PYNUSMV_VERSION" -d "$WORK/sdist"
SDIST="$(ls "$WORK"/sdist/pynusmv-*.tar.gz 2>/dev/null | head -n1)"
[ -n "$SDIST" ] || die "pip did not produce a pynusmv sdist"
run_logged "extract NuSMV-2.5.4.tar.gz from $(basename "$SDIST")" \
    tar -xzf "$SDIST" -C "$WORK" "pynusmv-$PYNUSMV_VERSION/dependencies/NuSMV/NuSMV-2.5.4.tar.gz"
run_logged "unpack NuSMV-2.5.4" \
    tar -xzf "$WORK/pynusmv-$PYNUSMV_VERSION/dependencies/NuSMV/NuSMV-2.5.4.tar.gz" -C "$WORK"
SRC="$WORK/NuSMV-2.5.4"
[ -d "$SRC/cudd-2.4.1.1" ] && [ -d "$SRC/nusmv" ] || die "unexpected layout in NuSMV-2.5.4.tar.gz"

# --- fixes for a modern gcc --------------------------------------------------------------------
say "patch CUDD util/pipefork.c (union wait -> int)"
sed -i 's/union wait status;/int status;/' "$SRC/cudd-2.4.1.1/util/pipefork.c"
grep -q 'union wait' "$SRC/cudd-2.4.1.1/util/pipefork.c" && die "pipefork.c patch did not apply"

# --- CUDD --------------------------------------------------------------------------------------
CUDD_XCFLAGS="-DHAVE_IEEE_754 -DBSD -DNUSMV_SIZEOF_VOID_P=8 -DNUSMV_SIZEOF_LONG=8 -DNUSMV_SIZEOF_INT=4 -fcommon -std=gnu89"
# CUDD's Makefiles do not support parallel builds reliably; it is small.
run_logged "build CUDD (make -f Makefile_64bit)" \
    make -C "$SRC/cudd-2.4.1.1" -f Makefile_64bit "XCFLAGS=$CUDD_XCFLAGS" "CC=gcc" "ICFLAGS=-g -O2"
[ -f "$SRC/cudd-2.4.1.1/lib/libcudd.a" ] || die "CUDD build produced no lib/libcudd.a"

# --- NuSMV -------------------------------------------------------------------------------------
cd "$SRC/nusmv"
run_logged "configure NuSMV (CFLAGS=-fcommon -std=gnu89)" \
    ./configure --prefix="$PREFIX" --disable-dependency-tracking \
    CFLAGS="-O2 -fcommon -std=gnu89 -w" CXXFLAGS="-O2 -fcommon -w"
run_logged "build NuSMV (make -j$JOBS)" make -j"$JOBS"
[ -x "$SRC/nusmv/NuSMV" ] || die "NuSMV build produced no binary"

mkdir -p "$PREFIX/bin"
cp "$SRC/nusmv/NuSMV" "$BIN.tmp"
mv "$BIN.tmp" "$BIN"
binary_works "$BIN" || die "built binary $BIN does not run"
END=$(date +%s)
say "done in $((END - START)) s: $BIN"
"$BIN" -h 2>&1 | head -n 2 | sed 's/^/[build_nusmv] /' || true
