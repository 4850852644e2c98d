#!/usr/bin/env bash
# Install what is missing, build optimized with assertions on, and run the whole test suite.
# The psq slurm tests need a SLURM cluster: a single-node one on localhost is started before
# the tests and stopped after them, however they end.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh build RelWithDebInfo
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
trap '$SUDO ./scripts/slurm-localhost.sh stop' EXIT
# Without the cluster only the Slurm tests fail (they say why); the rest still run.
$SUDO ./scripts/slurm-localhost.sh start ||
  echo "test.sh: the localhost SLURM cluster did not start; the Slurm tests will fail" >&2
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 900
./scripts/fuzz.sh  # the fuzz targets, briefly (about 3 minutes on 2 cores; docs/fuzzing.md)
