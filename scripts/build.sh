#!/usr/bin/env bash
# Configures and builds PSQ in the given build directory with the given build type.
# Usage: scripts/build.sh BUILD_DIR BUILD_TYPE [cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=$1 build_type=$2
shift 2
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="$build_type" "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
