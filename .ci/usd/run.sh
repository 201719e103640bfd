#!/usr/bin/env bash
# `pelt export ... -o *.usda` checked with Pixar's own USD library: exports strands (the bunny; the
# groomed Fox as linear and as Catmull-Rom curves, thinned; the walking Fox with time samples; a
# soaked bunny), then .ci/usd/check.py opens each with usd-core and compares it with the `usd:`
# line pelt printed. Takes the `pelt` CI's tests built (PELT_BIN; no second profile); the virtual
# environment is kept in the target folder, so a warm run installs nothing.
set -euo pipefail
cd "$(dirname "$0")/../.."
target="${CARGO_TARGET_DIR:-target}"
# PELT_BIN: a `pelt` already built (CI passes the one its tests built); else one is built here.
pelt="${PELT_BIN:-}"
if [ -z "$pelt" ]; then
  cargo build -p pelt --locked
  pelt="$target/debug/pelt"
fi
bash .ci/usd/venv.sh
venv="$target/usd-venv"
out="$target/usd-check"
rm -rf "$out"
mkdir -p "$out"
check() {
  local name=$1
  shift
  "$pelt" export "$@" -o "$out/$name.usda" | tee "$out/$name.txt"
  "$venv/bin/python" .ci/usd/check.py "$out/$name.usda" "$(grep '^usd: ' "$out/$name.txt")"
}
check bunny --builtin bunny
check fox-groomed assets/meshes/Fox.glb --preset assets/presets/fox_groomed.toml
check fox-cubic assets/meshes/Fox.glb --preset assets/presets/fox.toml --curves catmull-rom --strand-fraction 0.25
check fox-walk assets/meshes/Fox.glb --preset assets/presets/fox.toml --animation Walk --time 0.5 --motion 0.5 \
  --strand-fraction 0.1
check bunny-soaked --builtin bunny --wetness 1 --strand-fraction 0.5
