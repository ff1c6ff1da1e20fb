#!/usr/bin/env bash
# Build BehaviorTree.CPP 4.8.2 and the LEBT driver into the machine's cache (~/.cache/fsmbt). The build script ships inside the
# package (src/fsmbt/install/build_btcpp.sh), so an installed fsmbt runs the same one with
# `fsmbt doctor --install btcpp`; this is the checkout's entry point (scripts/setup.sh). Its
# environment variables are documented there.
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export FSMBT_CHECKOUT="$REPO_ROOT"
exec bash "$REPO_ROOT/src/fsmbt/install/build_btcpp.sh" "$@"
