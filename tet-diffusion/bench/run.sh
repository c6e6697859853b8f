#!/usr/bin/env bash
# Issue #44's peers: exports the transcut example's systems (release build,
# its --json rows saved to target/peers-mtx/trilux.jsonl), then solves each
# exported system with scipy's Jacobi-preconditioned CG and pyamg's smoothed
# aggregation to the same 1 % error, one thread (peers.py, in a venv under
# target/), and prints the Markdown table of both. Arguments go to the
# example; PEERS_ARGS (e.g. "--repeats 9") to peers.py. Usage, from anywhere:
#
#     TRILUX_DATA=../shared/data bash tet-diffusion/bench/run.sh [--repeat 5]
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV=target/peers-venv
OUT=target/peers-mtx
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip
# scipy >= 1.12 for cg's rtol and the fast mmread.
"$VENV/bin/python" -m pip install -q "numpy>=2,<3" "scipy>=1.12,<2" "pyamg>=5,<6"
# A fresh folder: every system is exported and solved in this run.
rm -rf "$OUT"
mkdir -p "$OUT"
cargo run --release -p tet-diffusion --example transcut -- --json --export-mtx "$OUT" "$@" |
  tee "$OUT/trilux.jsonl" >&2
# shellcheck disable=SC2086 # PEERS_ARGS is split on purpose
exec "$VENV/bin/python" tet-diffusion/bench/peers.py "$OUT" --markdown --out "$OUT/peers.jsonl" ${PEERS_ARGS:-}
