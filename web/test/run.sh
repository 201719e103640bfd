#!/usr/bin/env bash
# Builds the web page and checks it in headless Chromium (Debian's `chromium`, its WebGPU on
# SwiftShader). Installs what a fresh Debian 12 machine lacks: chromium, node and npm from apt,
# puppeteer-core from npm (no browser download). Idempotent; any failure fails the run.
set -euo pipefail
cd "$(dirname "$0")/../.."
# Each phase's wall time, for CI's budget (the web step may add at most 10 minutes).
phase() { echo "web/test/run.sh: $1 took $((SECONDS - phase_start)) s"; phase_start=$SECONDS; }
phase_start=$SECONDS

missing=()
for p in chromium nodejs npm; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || command -v "${p/nodejs/node}" >/dev/null || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
phase "apt (chromium, nodejs, npm)"

bash web/build.sh
phase "web/build.sh (wasm-bindgen-cli if missing, release wasm)"

cd web/test
PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-fund --no-audit --loglevel=error
phase "npm ci"
node --test --test-reporter=spec page.test.mjs
phase "browser test"
