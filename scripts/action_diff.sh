#!/usr/bin/env bash
# The script of fsmbt's GitHub Action (action.yml), runnable anywhere: diff every model file
# changed between FSMBT_BASE and FSMBT_HEAD in the current git repository, write the Markdown to
# FSMBT_OUT and print its path as the step output `markdown`.
#   FSMBT_BASE (required), FSMBT_HEAD (default HEAD), FSMBT_PATTERNS ("*.xml *.scxml"),
#   FSMBT_FAIL_ON_CHANGE (true|false), FSMBT_OUT (default fsmbt-diff.md), FSMBT (the fsmbt
#   command, default: fsmbt on PATH).
# Exit: fsmbt review' (0, 1 with FSMBT_FAIL_ON_CHANGE=true and a changed behaviour, 2 bad).
set -euo pipefail
: "${FSMBT_BASE:?FSMBT_BASE: the base revision}"
HEAD_REV="${FSMBT_HEAD:-HEAD}"
OUT="${FSMBT_OUT:-fsmbt-diff.md}"
FSMBT_CMD="${FSMBT:-fsmbt}"
set -f  # the patterns are passed to fsmbt, never expanded by the shell
args=(review "$FSMBT_BASE" "$HEAD_REV" --markdown "$OUT" --force)
for p in ${FSMBT_PATTERNS:-*.xml *.scxml}; do args+=(--pattern "$p"); done
[ "${FSMBT_FAIL_ON_CHANGE:-false}" = "true" ] && args+=(--fail-on-change)
# git refuses to work in a checkout owned by another user (actions/checkout in containers)
if [ "${GITHUB_ACTIONS:-}" = "true" ]; then
    git config --global --add safe.directory "$PWD" >/dev/null 2>&1 || true
fi
status=0
$FSMBT_CMD "${args[@]}" || status=$?
if [ -n "${GITHUB_OUTPUT:-}" ]; then echo "markdown=$OUT" >> "$GITHUB_OUTPUT"; fi
exit "$status"
