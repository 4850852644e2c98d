#!/bin/sh
# Coarse-first against refining everything, on a material × thickness sweep (docs/benchmarks.md,
# "Coarse-first sweeps"). Runs the sweep twice in fresh stores under OUT (default a temporary
# directory): once with refine = "none" (every preview, then `psq promote --top K` of the
# largest previewed displacements, timed separately), once with refine = "all". Then compares,
# on the refine = "all" run, the top-k selection made from the last preview level with the one
# made from the converged finest level, for every k and both outputs.
#
#   scripts/coarse_first_bench.sh [PSQ] [OUT] [K]      (defaults: build/psq, mktemp -d, 5)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
psq=$(realpath "${1:-$root/build/psq}")
out=${2:-$(mktemp -d)}
k=${3:-5}
mkdir -p "$out"
cp "$root/jobs/scenes/demo_strip.toml" "$out/scene.toml"

sweep() {  # sweep NAME REFINE
  cat > "$out/$1.toml" <<TOML
name = "$1"
scene = "scene.toml"
depth = 3
refine = $2

[grid]
"shell.strip.material.youngs_modulus" = [5e6, 2e7, 1e8, 5e8, 2e9]
"shell.strip.material.thickness" = [5e-4, 7.5e-4, 1e-3, 1.5e-3, 2e-3]
TOML
}

seconds() {  # seconds COMMAND...: runs it, prints its wall time
  start=$(date +%s.%N)
  "$@" > /dev/null 2>&1
  echo "$(date +%s.%N) - $start" | bc
}

sweep coarse '"none"'
sweep everything '"all"'
"$psq" sweep add "$out/coarse.toml" --db "$out/coarse/psq.db" > /dev/null
"$psq" sweep add "$out/everything.toml" --db "$out/everything/psq.db" > /dev/null
preview=$(seconds "$psq" work --workers 1 --db "$out/coarse/psq.db")
"$psq" promote coarse --top "$k" --by max_displacement --db "$out/coarse/psq.db"
refine=$(seconds "$psq" work --workers 1 --db "$out/coarse/psq.db")
all=$(seconds "$psq" work --workers 1 --db "$out/everything/psq.db")
"$psq" results coarse --json --db "$out/coarse/psq.db" > "$out/coarse.json"
"$psq" results everything --json --db "$out/everything/psq.db" > "$out/everything.json"

python3 - "$out" "$preview" "$refine" "$all" "$k" <<'PY'
import json, sys
out, preview, refine, every, k = sys.argv[1], *map(float, sys.argv[2:5]), int(sys.argv[5])
coarse = json.load(open(f"{out}/coarse.json"))["jobs"]
jobs = json.load(open(f"{out}/everything.json"))["jobs"]
done = sum(j["state"] == "done" for j in coarse)
print(f"{len(jobs)} points, depth 3 (preview: levels 0-1)")
print(f"full preview        {preview:7.1f} s  ({preview / every:.0%} of refining everything)")
print(f"+ refine top {k:<2}     {refine:7.1f} s  ({done} jobs done)")
print(f"coarse-first total  {preview + refine:7.1f} s  ({(preview + refine) / every:.0%})")
print(f"refine everything   {every:7.1f} s")

def top(level, output, count):
    ranked = sorted(jobs, key=lambda j: -j["levels"][level]["outputs"][output])
    return {j["id"] for j in ranked[:count]}

for output in ("max_displacement", "elastic_energy"):
    exact = sum(top(1, output, n) == top(2, output, n) for n in range(1, len(jobs)))
    overlap = [len(top(1, output, n) & top(2, output, n)) / n for n in range(1, len(jobs))]
    print(f"{output}: preview top-k = converged top-k for {exact} of {len(jobs) - 1} k; "
          f"mean overlap {sum(overlap) / len(overlap):.0%}, worst {min(overlap):.0%}; "
          f"top {k}: {len(top(1, output, k) & top(2, output, k))} of {k} match")
PY
