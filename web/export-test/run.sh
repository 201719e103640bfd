#!/usr/bin/env bash
# Exports fur with `pelt export` (bunny masked and blended, the try-on garment as .gltf + .bin,
# the Fox at rest, mid-walk and groomed, a morph-target ball, the bunny with --motion), renders the bunny with `pelt render` at the test's camera, and
# checks the files with the Khronos glTF Validator and three.js in headless Chromium
# (export.test.mjs). Needs chromium, node and npm (web/test/install.sh installs them) and a Vulkan
# adapter for `pelt render` (lavapipe in CI). Any failure, validator warnings included, fails it.
set -euo pipefail
cd "$(dirname "$0")/../.."
# PELT_BIN: a `pelt` already built (CI passes the one its tests built); else one is built here.
pelt="${PELT_BIN:-}"
if [ -z "$pelt" ]; then
  cargo build -p pelt --locked
  pelt="${CARGO_TARGET_DIR:-target}/debug/pelt"
fi
out=web/export-test/output
rm -rf "$out"
mkdir -p "$out"
"$pelt" export --builtin bunny -o "$out/bunny.glb"
"$pelt" export --builtin bunny --alpha blend -o "$out/bunny-blend.glb"
"$pelt" export --builtin tryon --layers 8 -o "$out/tryon.gltf"
"$pelt" export assets/meshes/Fox.glb --preset assets/presets/fox.toml -o "$out/fox.glb"
"$pelt" export assets/meshes/Fox.glb --preset assets/presets/fox.toml --animation Walk --time 0.5 --layers 8 \
  -o "$out/fox-walk.glb"
# A mesh with morph targets (its fur's roots follow them), and fur swaying in the wind as morph
# targets.
"$pelt" export assets/meshes/morph_ball.gltf --layers 8 -o "$out/ball.glb"
"$pelt" export assets/meshes/Fox.glb --preset assets/presets/fox_groomed.toml --layers 8 -o "$out/fox-groomed.glb"
"$pelt" export --builtin bunny --layers 8 --motion 1 -o "$out/bunny-motion.glb"
"$pelt" export assets/meshes/Fox.glb --preset assets/presets/fox.toml --layers 4 --motion 1 -o "$out/fox-motion.glb"
# The picture three.js must match: no wind (the export settles without), every layer; the camera
# is export.test.mjs's VIEW; the studio is page.html's (the paper's: Kajiya-Kay in a key light
# fixed to the camera, a uniform ambient, no shadows), which a standard PBR material can stand in for.
"$pelt" render --builtin bunny --wind 0,0,0 --no-lod --camera 30,15,24 --size 480x360 \
  --preset assets/presets/kajiya_kay.toml --light camera --no-shadows -o "$out/bunny-pelt.png"

bash web/test/install.sh
cd web/export-test
node --test --test-reporter=spec export.test.mjs
