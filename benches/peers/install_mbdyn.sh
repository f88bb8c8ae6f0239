#!/usr/bin/env bash
# Builds MBDyn from its public source into benches/peers/.mbdyn (git-ignored): Debian's
# current release has no package. Installs the build's dependencies from Debian's packages
# (apt-get, as root) once the source is there: the source tarball (MBDYN_URL) or, failing
# that, a clone of the public git repository (MBDYN_GIT); and builds with the flags a current GCC needs for this
# C++ and Fortran code. Builds in a temporary folder and moves the result into place only
# when it runs: nothing half-installed. Its last line says what happened.
#
#   bash benches/peers/install_mbdyn.sh
set -euo pipefail
cd "$(dirname "$0")"
dest=$PWD/.mbdyn
MBDYN_URL=${MBDYN_URL:-https://www.mbdyn.org/userfiles/downloads/mbdyn-1.7.3.tar.gz}
MBDYN_GIT=${MBDYN_GIT:-https://public.gitlab.polimi.it/DAER/mbdyn.git}
if [ -x "$dest/bin/mbdyn" ]; then
  echo "mbdyn already built in $dest ($("$dest/bin/mbdyn" --version 2>&1 | head -1))"
  exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
src=""
if curl -fsSL --max-time 120 -o "$work/mbdyn.tar.gz" "$MBDYN_URL" 2>"$work/curl.err"; then
  tar -xzf "$work/mbdyn.tar.gz" -C "$work"
  src=$(find "$work" -mindepth 1 -maxdepth 1 -type d -name 'mbdyn*' | head -1)
elif git clone -q --depth 1 "$MBDYN_GIT" "$work/mbdyn" 2>"$work/git.err"; then
  src=$work/mbdyn
  (cd "$src" && { [ -x ./bootstrap.sh ] && ./bootstrap.sh; } >/dev/null 2>&1 || autoreconf -fi >/dev/null 2>&1)
else
  echo "MBDyn's source could not be fetched: $MBDYN_URL: $(tail -1 "$work/curl.err"); $MBDYN_GIT: $(tail -1 "$work/git.err")"
  exit 1
fi
cd "$src"
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
  apt-get update -qq >/dev/null 2>&1 || true
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq build-essential gfortran autoconf automake \
    libtool libltdl-dev libsuitesparse-dev libblas-dev liblapack-dev curl git >/dev/null ||
    { echo "apt-get could not install MBDyn's build dependencies"; exit 1; }
fi
CXXFLAGS="-O2 -std=gnu++14" CFLAGS="-O2" FFLAGS="-O2 -fallow-argument-mismatch" \
  ./configure --prefix="$dest.tmp" >"$work/configure.log" 2>&1 ||
  { echo "MBDyn's configure failed: $(tail -1 "$work/configure.log")"; exit 1; }
nice -n 10 make -j2 >"$work/make.log" 2>&1 || { echo "MBDyn's build failed: $(tail -1 "$work/make.log")"; exit 1; }
rm -rf "$dest.tmp"
make install >"$work/install.log" 2>&1 || { rm -rf "$dest.tmp"; echo "MBDyn's make install failed"; exit 1; }
mv "$dest.tmp" "$dest"
echo "mbdyn built in $dest ($("$dest/bin/mbdyn" --version 2>&1 | head -1))"
