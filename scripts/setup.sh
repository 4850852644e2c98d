#!/usr/bin/env bash
# Installs the Debian packages PSQ needs, only those missing. Idempotent and non-interactive.
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread libopenblas-pthread-dev
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libhdf5-dev libsqlite3-dev sqlite3 libfmt-dev libtbb-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  gnuplot-nox  # plots in sweep reports (psq report)
  chromium     # headless browser: the test that opens the HTML report
  slurm-wlm munge  # the single-node SLURM cluster of the psq slurm tests (scripts/slurm-localhost.sh)
  clang libclang-rt-14-dev  # libFuzzer and its sanitizers for the fuzz targets (scripts/fuzz.sh)
  python3-meshio python3-h5py  # an independent XDMF reader for the sidecar tests (h5py: its HDF5)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
