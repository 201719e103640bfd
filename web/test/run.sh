#!/usr/bin/env bash
# Builds the web page and checks it in headless Chromium (Debian's `chromium`, its WebGPU on
# SwiftShader). Installs what a fresh Debian 12 machine lacks (web/test/install.sh: chromium, node
# and npm from apt, puppeteer-core from npm without a browser download). Idempotent; any failure
# fails the run.
set -euo pipefail
cd "$(dirname "$0")/../.."
# Each phase's wall time, for CI's budget (the web step may add at most 10 minutes).
phase() { echo "web/test/run.sh: $1 took $((SECONDS - phase_start)) s"; phase_start=$SECONDS; }
phase_start=$SECONDS

bash web/test/install.sh
phase "web/test/install.sh (chromium, nodejs, npm; npm packages)"

bash web/build.sh
phase "web/build.sh (wasm-bindgen-cli if missing, release wasm)"

cd web/test
node --test --test-reporter=spec page.test.mjs
phase "browser test"
