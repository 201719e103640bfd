#!/usr/bin/env bash
# Builds Pelt's web page into web/dist/ (index.html, main.js, the .wasm and its JS glue).
# Installs what it needs: the wasm32 target through rustup, and wasm-bindgen-cli from crates.io
# at the exact version of the wasm-bindgen crate in Cargo.lock. Idempotent.
# Serve it with: python3 -m http.server -d web/dist
set -euo pipefail
cd "$(dirname "$0")/.."

rustup target add wasm32-unknown-unknown >/dev/null 2>&1 || rustup target add wasm32-unknown-unknown

version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
if [ -z "$version" ]; then
  echo "web/build.sh: no wasm-bindgen in Cargo.lock" >&2
  exit 1
fi
bindgen="$HOME/.cargo/bin/wasm-bindgen"
if ! { [ -x "$bindgen" ] && "$bindgen" --version | grep -qx "wasm-bindgen $version"; }; then
  echo "installing wasm-bindgen-cli $version"
  # --locked: the CLI's own lock file, so its build is the one its authors tested. (0.2.130's lock
  # names webpki-roots 1.0.11, missing from some registry mirrors; hence wasm-bindgen 0.2.129.)
  cargo install --quiet --locked wasm-bindgen-cli --version "=$version"
fi

# Its own target dir: the web build's profile and target do not churn the native build's.
export CARGO_TARGET_DIR="${PELT_WEB_TARGET_DIR:-target/web}"
# Line tables help nobody in a download; size matters more there.
export CARGO_PROFILE_RELEASE_DEBUG=false
cargo build --locked --release -p pelt-web --target wasm32-unknown-unknown

out=web/dist
rm -rf "$out"
mkdir -p "$out"
"$bindgen" --target web --no-typescript --out-dir "$out" "$CARGO_TARGET_DIR/wasm32-unknown-unknown/release/pelt_web.wasm"
cp web/index.html web/main.js "$out/"
raw=$(stat -c %s "$out/pelt_web_bg.wasm")
gz=$(gzip -9 -c "$out/pelt_web_bg.wasm" | wc -c)
echo "web/dist: pelt_web_bg.wasm $raw bytes ($gz gzipped)"
