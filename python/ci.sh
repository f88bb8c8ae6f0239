#!/usr/bin/env bash
# Builds the Python package `mecano` and runs its tests (pytest), from a clean checkout:
# a virtual environment python/.venv with what python/requirements-ci.txt lists (maturin,
# numpy, pytest, from PyPI), the wheel built by maturin into target/wheels, installed into
# that environment, then `pytest python/tests`. `cargo test` runs this script
# (tests/python.rs), so the README's one test command covers the Python package too.
#
# The wheel is built with the dev profile given the test profile's settings (opt-level 2,
# line tables, no incremental: Cargo.toml's [profile.test]) in the workspace's target/, so
# the library and its dependencies `cargo test` compiled are reused (Cargo hashes a
# profile's settings, not its name): only PyO3, numpy and the extension crate are added.
# (`--profile test` would build the crate's test harness.) A release wheel for use is what
# `pip install ./python` builds.
#
# Environment: PYTHON (default python3), MECANO_PYTEST_ARGS (extra pytest arguments).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
py="${PYTHON:-python3}"
venv="$here/.venv"
stamp="$venv/.requirements.sha256"
want="$(sha256sum "$here/requirements-ci.txt" | cut -d' ' -f1)"
# The pip cache stays inside the repository's ignored folders: nothing is written to $HOME.
export PIP_CACHE_DIR="$root/target/pip-cache"
export PIP_DISABLE_PIP_VERSION_CHECK=1
if [[ ! -x "$venv/bin/python" ]] || [[ "$(cat "$stamp" 2>/dev/null)" != "$want" ]]; then
    rm -rf "$venv"
    "$py" -m venv "$venv"
    "$venv/bin/pip" install --quiet -r "$here/requirements-ci.txt"
    echo "$want" > "$stamp"
fi
cd "$here"
rm -f "$root"/target/wheels/mecano-*.whl
CARGO_PROFILE_DEV_OPT_LEVEL=2 CARGO_PROFILE_DEV_DEBUG=line-tables-only \
    CARGO_PROFILE_DEV_INCREMENTAL=false \
    "$venv/bin/maturin" build --quiet --interpreter "$venv/bin/python" \
    --out "$root/target/wheels"
"$venv/bin/pip" install --quiet --force-reinstall --no-deps "$root"/target/wheels/mecano-*.whl
cd "$root"
# -p no:cacheprovider: no .pytest_cache written into the checkout.
# shellcheck disable=SC2086
exec "$venv/bin/python" -m pytest -p no:cacheprovider -q python/tests ${MECANO_PYTEST_ARGS:-}
