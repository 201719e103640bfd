#!/usr/bin/env bash
# The USD check's virtual environment, in the target folder: Pixar's usd-core from PyPI (and
# python3-venv from apt where missing). Idempotent: a venv that imports pxr.Usd is kept. CI runs
# it while the build compiles.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv="${CARGO_TARGET_DIR:-target}/usd-venv"
if ! "$venv/bin/python" -c "import pxr.Usd" 2>/dev/null; then
  if ! python3 -m venv --help >/dev/null 2>&1 || ! python3 -c "import ensurepip" 2>/dev/null; then
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends python3-venv
  fi
  rm -rf "$venv"
  mkdir -p "$(dirname "$venv")"
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check usd-core==26.11
fi
