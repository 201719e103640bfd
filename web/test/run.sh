#!/usr/bin/env bash
# Builds the web page and checks it in headless Chromium (Debian's `chromium`, its WebGPU on
# SwiftShader). Installs what a fresh Debian 12 machine lacks: chromium, node and npm from apt,
# puppeteer-core from npm (no browser download). Idempotent; any failure fails the run.
set -euo pipefail
cd "$(dirname "$0")/../.."

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

bash web/build.sh

cd web/test
PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-fund --no-audit --loglevel=error
node --test --test-reporter=spec page.test.mjs
