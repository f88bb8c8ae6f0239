#!/usr/bin/env bash
# Installs the peers of the bench into git-ignored folders of benches/peers/ and says, per
# peer, whether it can be run: OUT/status/<peer>.ok (with its version) or OUT/status/<peer>.fail
# (why not). A peer that fails to install is reported and the others go on.
#
#   bash benches/peers/install.sh [OUT]        (default OUT: out/peers)
#
# Exudyn: pinned, from the Python package index, into the virtual environment
# benches/peers/.venv (with numpy, and matplotlib for the figures).
# MBDyn: built from its public source by benches/peers/install_mbdyn.sh into
# benches/peers/.mbdyn (Debian's current release has no package).
set -u
cd "$(dirname "$0")/../.."
out=${1:-out/peers}
st="$out/status"
mkdir -p "$st"
EXUDYN_VERSION=1.13.6
venv=benches/peers/.venv

ok() { rm -f "$st/$1.fail"; printf '%s\n' "$2" >"$st/$1.ok"; echo "peers: $1 ready ($2)"; }
fail() { rm -f "$st/$1.ok"; printf '%s\n' "$2" >"$st/$1.fail"; echo "peers: $1 NOT available: $2" >&2; }

# --- Exudyn
if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c "import exudyn, scipy, sys; sys.exit(exudyn.__version__ != '$EXUDYN_VERSION')" 2>/dev/null; then
  ok exudyn "exudyn $EXUDYN_VERSION (already in $venv)"
else
  log=$(mktemp)
  if { [ -x "$venv/bin/python" ] || python3 -m venv "$venv"; } >"$log" 2>&1 &&
    nice -n 10 "$venv/bin/pip" install --disable-pip-version-check -q numpy scipy matplotlib >>"$log" 2>&1 &&
    nice -n 10 "$venv/bin/pip" install --disable-pip-version-check -q "exudyn==$EXUDYN_VERSION" >>"$log" 2>&1 &&
    "$venv/bin/python" -c "import exudyn" >>"$log" 2>&1; then
    ok exudyn "exudyn $EXUDYN_VERSION ($venv)"
  else
    fail exudyn "pip install exudyn==$EXUDYN_VERSION into $venv failed: $(tail -1 "$log")"
  fi
  rm -f "$log"
fi

# --- MBDyn (a build from source: tens of minutes on two cores the first time)
[ -x benches/peers/.mbdyn/bin/mbdyn ] || echo "peers: building MBDyn from its source (benches/peers/install_mbdyn.sh; tens of minutes the first time) ..."
if msg=$(bash benches/peers/install_mbdyn.sh 2>&1 | tail -1) && [ -x benches/peers/.mbdyn/bin/mbdyn ]; then
  ok mbdyn "$msg"
else
  fail mbdyn "$msg"
fi
exit 0
