#!/usr/bin/env bash
# The full default evaluation (issue 15) with one kill and one resume, then the figures
# docs/evaluation.md records: run time of each part, rows at the kill, rows == jobs == distinct
# keys. One command for the rerun after a merge:
#
#   FSMBT_CORPUS=/work/shared/corpus FSMBT_NUSMV=... scripts/evaluate_full.sh [OUT] [KILL_AFTER]
#
# OUT (default /tmp/evalfull) must not exist: nothing is overwritten. KILL_AFTER (seconds,
# default 60): when the first run gets SIGKILL (its whole process group). DOCS_PLOTS=1 copies
# the run's PNG plots into docs/evaluation/. Runs under `nice -n 10`. Exit 1 when the counts
# do not match (a lost or duplicated row).
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO_ROOT"
VENV="${FSMBT_VENV:-$REPO_ROOT/.venv}"
PY="$VENV/bin/python"
export PYTHONPATH="$REPO_ROOT/src${PYTHONPATH:+:$PYTHONPATH}"
OUT="${1:-/tmp/evalfull}"
KILL_AFTER="${2:-60}"
CORPUS="${FSMBT_CORPUS:-$REPO_ROOT/../shared/corpus}"
if [ -e "$OUT" ]; then
    echo "evaluate_full: $OUT exists; remove it or name another folder (nothing is overwritten)" >&2
    exit 2
fi
if [ ! -d "$CORPUS" ]; then
    echo "evaluate_full: no corpus at $CORPUS (set FSMBT_CORPUS); the run would leave it out" >&2
    exit 2
fi
echo "corpus: $CORPUS; report folder: $OUT; kill after ${KILL_AFTER} s"

now() { "$PY" -c 'import time; print(f"{time.time():.3f}")'; }
count_rows() {
    "$PY" - "$OUT/results.sqlite" <<'EOF'
import sqlite3, sys
try:
    with sqlite3.connect(sys.argv[1]) as db:
        # finished rows only: a job handed out when the kill came has a 'pending' claim row
        rows, keys = db.execute(
            "SELECT COUNT(*), COUNT(DISTINCT key) FROM results"
            " WHERE state = 'done' AND NOT COALESCE(retry, 0)"
        ).fetchone()
        pending = db.execute("SELECT COUNT(*) FROM results WHERE state = 'pending'").fetchone()[0]
except sqlite3.Error:
    rows, keys, pending = 0, 0, 0
print(rows, keys, pending)
EOF
}

started=$(now)
# its own session, so the group id is its pid and SIGKILL reaches every worker process
setsid nice -n 10 "$PY" -m fsmbt.cli evaluate -o "$OUT" --corpus "$CORPUS" --quiet \
    >"$OUT.part1.log" 2>&1 &
first=$!
sleep "$KILL_AFTER"
if kill -0 "$first" 2>/dev/null; then
    kill -KILL -- "-$first"
    killed=1
else
    killed=0
fi
wait "$first" 2>/dev/null || true
killed_at=$(now)
read -r rows_at_kill keys_at_kill pending_at_kill < <(count_rows)
echo "part 1: killed=$killed after $("$PY" -c "print(round($killed_at - $started, 1))") s;" \
    "finished rows stored $rows_at_kill, distinct keys $keys_at_kill;" \
    "claimed but unfinished (pending) $pending_at_kill"

resumed=$(now)
nice -n 10 "$PY" -m fsmbt.cli evaluate -o "$OUT" --corpus "$CORPUS" --quiet \
    | tee "$OUT.part2.log"
finished=$(now)
read -r rows keys pending < <(count_rows)

status=0
"$PY" - "$OUT" "$started" "$killed_at" "$resumed" "$finished" "$rows_at_kill" "$rows" "$keys" \
    "$killed" "$pending" <<'EOF' || status=$?
import json, sys
from pathlib import Path
out = Path(sys.argv[1])
started, killed_at, resumed, finished = map(float, sys.argv[2:6])
rows_at_kill, rows, keys, killed, pending = map(int, sys.argv[6:11])
runs = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines() if line]
last = runs[-1]
run = json.loads((out / "run.json").read_text())
ok = (
    rows == keys == last["jobs"] == last["after"]
    and last["before"] == rows_at_kill
    and pending == 0
)
print(f"models {run['models']}, jobs {last['jobs']}")
print(f"kills {killed}, resumes {killed}, completed invocations logged {len(runs)}")
print(f"part 1 (killed): {killed_at - started:.1f} s, {rows_at_kill} rows stored")
print(f"part 2 (resumed): found {last['before']}, ran {last['ran']}, stored after {last['after']};"
      f" batch {last['seconds']:.1f} s, with the report {finished - resumed:.1f} s")
print(f"total wall time {finished - started:.1f} s")
print(f"rows {rows} == jobs {last['jobs']} == distinct keys {keys}, {pending} pending left,"
      f" resume found exactly the rows stored at the kill: {'yes' if ok else 'NO'}")
sys.exit(0 if ok else 1)
EOF
if [ "${DOCS_PLOTS:-0}" = "1" ]; then
    mkdir -p docs/evaluation
    cp "$OUT"/plots/*.png docs/evaluation/
    echo "plots copied to docs/evaluation/"
fi
echo "report: $OUT/report.md"
exit $status
