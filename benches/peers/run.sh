#!/usr/bin/env bash
# The peer bench by one command (docs/performance.md): installs the peers (pinned; a peer
# that cannot be installed is reported and the bench goes on without it), builds mecano-rs
# in release, runs every scene's reference and each code's ladder one after the other on
# this machine, and prints docs/performance.md's tables (also in OUT/tables.md, with the
# figures OUT/<scene>.png/.svg). Arguments go to bench.py (--scenes, --codes, --rounds, --quick).
#
#   bash benches/peers/run.sh [--rounds 3] [--scenes cantilever,spinup]
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${PEERS_OUT:-out/peers}
bash benches/peers/install.sh "$out"
nice -n 10 cargo build --release --quiet
py=python3
[ -x benches/peers/.venv/bin/python ] && py=benches/peers/.venv/bin/python
exec nice -n 5 "$py" benches/peers/bench.py --out "$out" "$@"
