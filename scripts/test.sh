#!/usr/bin/env bash
# Install what is missing, build optimized with assertions on, and run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh build RelWithDebInfo
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 900
