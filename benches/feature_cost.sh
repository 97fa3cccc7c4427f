#!/usr/bin/env bash
# What a feature costs a scene that does not use it: the scenes benchmark
# built with the feature (default) and without it (a build that never had
# it), run alternately on the same scene; prints each run and the ratio of
# the medians. Usage: benches/feature_cost.sh [SCENE] [STEPS] [ROUNDS]
#   benches/feature_cost.sh large_pyramid 200 5
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-large_pyramid}
steps=${2:-200}
rounds=${3:-5}
cargo build --release --bench scenes --target-dir target/with-portals >/dev/null 2>&1
cargo build --release --bench scenes --no-default-features --target-dir target/without-portals >/dev/null 2>&1
bin() { ls -t "target/$1/release/deps/"scenes-* | grep -v '\.d$' | head -1; }
with=$(bin with-portals)
without=$(bin without-portals)
w=(); o=()
for r in $(seq "$rounds"); do
  a=$("$with" "$scene" -s "$steps" -r 1 --csv | tail -1 | cut -d, -f7)
  b=$("$without" "$scene" -s "$steps" -r 1 --csv | tail -1 | cut -d, -f7)
  echo "round $r: with portals ${a} ms/step, without the feature ${b} ms/step"
  w+=("$a"); o+=("$b")
done
python3 - "${w[*]}" "${o[*]}" <<'PY'
import statistics, sys
w = [float(x) for x in sys.argv[1].split()]
o = [float(x) for x in sys.argv[2].split()]
mw, mo = statistics.median(w), statistics.median(o)
print(f"median with portals {mw:.3f} ms/step, without {mo:.3f} ms/step, ratio {mw / mo:.4f}")
PY
