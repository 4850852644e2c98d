#!/usr/bin/env bash
# The main job: install what is missing, build optimized, run the demo sweep (jobs/sweeps/demo.toml)
# in a fresh workspace out/demo with the embedded SQLite store, and print the report's path.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh build-release Release -DPSQ_BUILD_TESTS=OFF
rm -rf out/demo
mkdir -p out/demo
psq=./build-release/psq
db=out/demo/psq.db
"$psq" sweep add jobs/sweeps/demo.toml --db "$db"
"$psq" work --db "$db"
"$psq" status --db "$db"
"$psq" report demo --db "$db" --out out/demo/report
echo "report: $(pwd)/out/demo/report/report.html"
