#!/usr/bin/env bash
# Builds MBDyn from its public source into benches/peers/.mbdyn (git-ignored): Debian's
# current release has no package. The source, first found of:
#   MBDYN_SRC  a local copy: a git directory (bare or not: its HEAD is exported) or a source tree
#   MBDYN_URL  the release tarball (default: mbdyn.org's 1.7.3)
#   MBDYN_GIT  the public git repository (default: Politecnico di Milano's GitLab)
# Installs the build's dependencies from Debian's packages (apt-get, as root), bootstraps the
# autotools files when the source has none (a git checkout), configures a lean build (no
# optional module: no NetCDF, MPI, Octave, Python, RTAI, GiNaC, METIS; UMFPACK for the sparse
# LU) with the flags a current GCC needs for this C++ and Fortran code
# (CXXFLAGS=-std=gnu++14, FFLAGS=-fallow-argument-mismatch), builds with `nice make -j2`.
# Builds in a temporary folder and moves the result into place only when the binary runs:
# nothing half-installed. The logs of the last attempt stay in benches/peers/.mbdyn-build/.
# Its last line says what happened.
#
#   bash benches/peers/install_mbdyn.sh
#   MBDYN_SRC=/path/to/mbdyn.git bash benches/peers/install_mbdyn.sh
set -euo pipefail
cd "$(dirname "$0")"
dest=$PWD/.mbdyn
logs=$PWD/.mbdyn-build
MBDYN_URL=${MBDYN_URL:-https://www.mbdyn.org/userfiles/downloads/mbdyn-1.7.3.tar.gz}
MBDYN_GIT=${MBDYN_GIT:-https://public.gitlab.polimi.it/DAER/mbdyn.git}
if [ -x "$dest/bin/mbdyn" ]; then
  echo "mbdyn already built in $dest ($("$dest/bin/mbdyn" --version 2>&1 | grep -m1 -i 'mbdyn' || echo '?'))"
  exit 0
fi
rm -rf "$logs" && mkdir -p "$logs"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
src=$work/mbdyn
mkdir -p "$src"
if [ -n "${MBDYN_SRC:-}" ]; then
  if git --git-dir="$MBDYN_SRC" rev-parse --verify -q HEAD >/dev/null 2>&1; then
    git --git-dir="$MBDYN_SRC" archive HEAD | tar -x -C "$src" ||
      { echo "MBDyn's source could not be exported from the git directory $MBDYN_SRC"; exit 1; }
    what="$MBDYN_SRC at $(git --git-dir="$MBDYN_SRC" rev-parse --short HEAD)"
  elif [ -f "$MBDYN_SRC/configure.ac" ]; then
    cp -a "$MBDYN_SRC/." "$src/"
    what="the source tree $MBDYN_SRC"
  else
    echo "MBDYN_SRC=$MBDYN_SRC is neither a git directory nor an MBDyn source tree (no configure.ac)"
    exit 1
  fi
elif curl -fsSL --max-time 120 -o "$work/mbdyn.tar.gz" "$MBDYN_URL" 2>"$logs/curl.err"; then
  tar -xzf "$work/mbdyn.tar.gz" -C "$src" --strip-components=1
  what=$MBDYN_URL
elif git clone -q --depth 1 "$MBDYN_GIT" "$src.git" 2>"$logs/git.err"; then
  rm -rf "$src" && mv "$src.git" "$src"
  what=$MBDYN_GIT
else
  echo "MBDyn's source could not be fetched: $MBDYN_URL: $(tail -1 "$logs/curl.err"); $MBDYN_GIT: $(tail -1 "$logs/git.err") (MBDYN_SRC= a local copy)"
  exit 1
fi
echo "mbdyn: building $what in $work" >&2
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
  apt-get update -qq >/dev/null 2>&1 || true
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq build-essential gfortran autoconf automake \
    libtool libltdl-dev libsuitesparse-dev libblas-dev liblapack-dev >"$logs/apt.log" 2>&1 ||
    { echo "apt-get could not install MBDyn's build dependencies: $(tail -1 "$logs/apt.log")"; exit 1; }
fi
cd "$src"
if [ ! -x ./configure ]; then
  sh ./bootstrap.sh >"$logs/bootstrap.log" 2>&1 ||
    { echo "MBDyn's bootstrap.sh (autotools) failed: $(tail -1 "$logs/bootstrap.log")"; exit 1; }
fi
CPPFLAGS="-I/usr/include/suitesparse" CXXFLAGS="-O2 -std=gnu++14" CFLAGS="-O2" \
  FFLAGS="-O2 -fallow-argument-mismatch" \
  ./configure --prefix="$dest" --with-umfpack --disable-runtime-loading --disable-netcdf \
  --without-metis --without-ginac --without-mpi --disable-octave --disable-python --without-rtai \
  --without-arpack --without-bullet --without-superlu --without-charm --enable-multithread=no \
  >"$logs/configure.log" 2>&1 ||
  { echo "MBDyn's configure failed: $(grep -m1 'error:' "$logs/configure.log" || tail -1 "$logs/configure.log")"; exit 1; }
nice -n 10 make -j2 >"$logs/make.log" 2>&1 ||
  { echo "MBDyn's build failed: $(grep -m1 -E 'error|Error' "$logs/make.log" || tail -1 "$logs/make.log")"; exit 1; }
# staged install (DESTDIR): the files land in $dest only by the final move
make install DESTDIR="$work/stage" >"$logs/install.log" 2>&1 ||
  { echo "MBDyn's make install failed: $(tail -1 "$logs/install.log")"; exit 1; }
LD_LIBRARY_PATH="$work/stage$dest/lib" "$work/stage$dest/bin/mbdyn" --version >"$logs/version.log" 2>&1 ||
  { echo "the MBDyn just built does not run: $(tail -1 "$logs/version.log")"; exit 1; }
# (one of MBDyn's Makefiles, build/, makes an empty $dest/libexec ignoring DESTDIR: no
# binary is there, the check at the top said so, so the folder is replaced whole)
rm -rf "$dest"
mv "$work/stage$dest" "$dest"
echo "mbdyn built in $dest from $what ($(grep -m1 -i 'mbdyn' "$logs/version.log" || echo '?'))"
