#!/usr/bin/env bash
# The package as users get it: build the sdist and the wheel (python -m build), install the wheel
# with pip into a fresh virtual env, and run fsmbt from there with HOME an empty folder, outside
# the checkout (nothing of src/ importable), with no NuSMV and no C++ build in reach:
#   1. the package data is there (web page assets and template, C++ runtime sources, LLM prompt
#      templates, the simulation models, the engines' build scripts): checked through the
#      installed package, never the checkout (the built-in node libraries are Python modules);
#   2. fsmbt convert + fsmbt verify on the examples (native checker) succeed;
#   3. fsmbt runtime cpp writes the C++ runtime (header, CMake example) from the package;
#   4. fsmbt doctor --json says NuSMV and the C++ runtime are missing and how to get them.
# pip's download cache is the machine's (PIP_CACHE_DIR, read before HOME is emptied): a cache of
# downloads, not state fsmbt reads. Prints the build, install and smoke times; about a minute.
#
#   bash scripts/check_wheel.sh        (CI: .ci/run)
# Environment: FSMBT_VENV, the venv with `build` (default: the checkout's .venv).
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${FSMBT_VENV:-$REPO_ROOT/.venv}"
say() { printf '[check_wheel] %s\n' "$*"; }
die() { printf '[check_wheel] FAILED: %s\n' "$*" >&2; exit 1; }

WORK="$(mktemp -d "${TMPDIR:-/tmp}/fsmbt-wheel.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT
export PIP_CACHE_DIR="${PIP_CACHE_DIR:-$("$VENV/bin/python" -m pip cache dir 2>/dev/null || echo "$WORK/pip-cache")}"
started=$(date +%s)

say "python -m build (sdist and wheel)"
"$VENV/bin/python" -m build --sdist --wheel --outdir "$WORK/dist" "$REPO_ROOT" >"$WORK/build.log" 2>&1 \
    || { tail -n 30 "$WORK/build.log" >&2; die "python -m build"; }
wheel="$(ls "$WORK"/dist/fsmbt-*.whl)"
sdist="$(ls "$WORK"/dist/fsmbt-*.tar.gz)"
say "built $(basename "$wheel") and $(basename "$sdist") in $(( $(date +%s) - started )) s"
tar -tzf "$sdist" >"$WORK/sdist.txt"
grep -q "src/fsmbt/install/build_nusmv.sh" "$WORK/sdist.txt" || die "the sdist lacks the build scripts"

mark=$(date +%s)
HOME_DIR="$WORK/home"
mkdir -p "$HOME_DIR"
python_bin="$(command -v python3.11 || command -v python3)"
"$python_bin" -m venv "$WORK/venv"
"$WORK/venv/bin/python" -m pip install --quiet --no-compile "$wheel" >"$WORK/pip.log" 2>&1 \
    || { tail -n 30 "$WORK/pip.log" >&2; die "pip install of the wheel"; }
say "installed into a fresh venv in $(( $(date +%s) - mark )) s"

mark=$(date +%s)
SMOKE="$WORK/smoke"
mkdir -p "$SMOKE"
cp "$REPO_ROOT/examples/robot_bt.xml" "$REPO_ROOT/examples/paper_fsm.xml" "$SMOKE/"
cd "$SMOKE"
run() {  # an installed-fsmbt command with an empty HOME, no cache override, no checkout on the path
    env -i PATH="$WORK/venv/bin:/usr/bin:/bin" HOME="$HOME_DIR" LANG=C.UTF-8 "$@"
}
run python - <<'EOF' || die "package data missing from the wheel"
import pathlib, sys
import fsmbt
root = pathlib.Path(fsmbt.__file__).parent
assert "site-packages" in str(root), root  # the installed package, not a checkout
need = [
    "web/templates/index.html", "web/static/app.js", "web/static/vendor/svg-pan-zoom.min.js",
    "runtime/cpp/include/fsmbt/lebt.hpp", "runtime/cpp/driver/fsmbt_lebt_driver.cpp",
    "install/build_nusmv.sh", "install/build_btcpp.sh",
    "llm/templates/fsm_to_bt.v1.md", "sim/models/prey_bt.xml", "sim/models/predator_fsm.scxml",
    "evaluate/templates/report.md.j2",
]
missing = [n for n in need if not (root / n).is_file()]
if missing:
    sys.exit(f"missing from the installed package: {missing}")
EOF
run fsmbt convert paper_fsm.xml -o paper_bt.xml >convert1.log 2>&1 || { cat convert1.log >&2; die "convert paper_fsm.xml"; }
grep -q "EQUIVALENT" convert1.log || { cat convert1.log >&2; die "convert did not prove the paper FSM's conversion"; }
run fsmbt convert robot_bt.xml -o robot_fsm.json >convert2.log 2>&1 || { cat convert2.log >&2; die "convert robot_bt.xml"; }
run fsmbt verify paper_fsm.xml paper_bt.xml >verify.log 2>&1 || { cat verify.log >&2; die "verify"; }
grep -q "EQUIVALENT" verify.log || { cat verify.log >&2; die "verify did not say EQUIVALENT"; }
run fsmbt runtime cpp cpp_out >runtime.log 2>&1 || { cat runtime.log >&2; die "runtime cpp"; }
[ -s cpp_out/include/fsmbt/lebt.hpp ] || die "runtime cpp wrote no header"
set +e
run fsmbt doctor --json >doctor.json 2>doctor.err
doctor=$?
set -e
[ "$doctor" = "1" ] || { cat doctor.json doctor.err >&2; die "doctor exit $doctor (expected 1: NuSMV missing)"; }
run python - <<'EOF' || die "doctor --json"
import json
checks = {c["name"]: c for c in json.load(open("doctor.json"))}
nusmv = checks["NuSMV"]
assert not nusmv["ok"] and "fsmbt doctor --install nusmv" in nusmv["hint"], nusmv
assert not checks["C++ LEBT driver"]["ok"], checks["C++ LEBT driver"]
assert all(c["adds"] for c in checks.values()), checks
EOF
leftover="$(find "$HOME_DIR" -mindepth 1 | head -n 5)"
say "smoke test passed in $(( $(date +%s) - mark )) s (convert, verify, runtime cpp, doctor)"
[ -z "$leftover" ] || say "files fsmbt left in the empty HOME: $leftover"
say "done in $(( $(date +%s) - started )) s"
