#!/usr/bin/env bash
# The main job: install what is missing, build optimized, run the demo, print where the results are.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh build-release Release -DPSQ_BUILD_TESTS=OFF
./build-release/psq sim jobs/scenes/drape.toml --out out/drape
