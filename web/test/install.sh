#!/usr/bin/env bash
# Installs what the browser checks need (web/test and web/export-test): chromium, node and npm
# from apt where missing, and each folder's npm packages (puppeteer-core without a browser
# download; the glTF validator and three.js). Idempotent: a folder whose node_modules came from
# its current package-lock.json is left alone. CI runs it while the build compiles.
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

for dir in web/test web/export-test; do
  # `npm ci` always starts node_modules afresh; the copy of the lock file it was made from says
  # whether it is current.
  if ! cmp -s "$dir/package-lock.json" "$dir/node_modules/.pelt-package-lock.json"; then
    (cd "$dir" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-fund --no-audit --loglevel=error)
    cp "$dir/package-lock.json" "$dir/node_modules/.pelt-package-lock.json"
  fi
done
