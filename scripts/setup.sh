#!/usr/bin/env bash
# Installs everything the tests and the browser build need on a fresh Debian machine that has only rustup.
# Each step is skipped when its tool is already present, so a rerun costs seconds.
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi

# --native: only what the CLI needs (a Vulkan driver). --web: only what building and serving the page
# needs (the wasm target, wasm-bindgen-cli, Node.js for the static server). Default: everything the
# tests need, both of those included.
mode=${1:-all}
case "$mode" in
  all|--native|--web) ;;
  *) echo "setup: unknown option '$mode' (expected --native, --web or nothing)" >&2; exit 2 ;;
esac

need_apt=()
[ "$mode" = --web ] || dpkg -s mesa-vulkan-drivers >/dev/null 2>&1 || need_apt+=(mesa-vulkan-drivers)
if [ "$mode" = --web ]; then
command -v node >/dev/null 2>&1 || need_apt+=(nodejs)
elif [ "$mode" = all ]; then
command -v chromium >/dev/null 2>&1 || need_apt+=(chromium)
command -v chromedriver >/dev/null 2>&1 || need_apt+=(chromium-driver)
command -v node >/dev/null 2>&1 || need_apt+=(nodejs)
command -v npm >/dev/null 2>&1 || need_apt+=(npm)
# the simulator check (tests/sim) needs a Python with venv + ensurepip; Debian splits them into python3-venv
command -v python3 >/dev/null 2>&1 || need_apt+=(python3)
python3 -c 'import venv, ensurepip' >/dev/null 2>&1 || need_apt+=(python3-venv)
fi
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "setup: installing apt packages: ${need_apt[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need_apt[@]}" >/dev/null
fi

if [ "$mode" = --native ]; then echo "setup: ok (native)"; exit 0; fi

if ! rustup target list --installed | grep -q '^wasm32-unknown-unknown$'; then
  echo "setup: adding the wasm32-unknown-unknown target"
  rustup target add wasm32-unknown-unknown
fi
if [ "$mode" = all ]; then
  for comp in rustfmt clippy; do
    rustup component list --installed | grep -q "^$comp" || rustup component add "$comp"
  done
fi

# wasm-bindgen-cli must match the wasm-bindgen crate in Cargo.lock exactly.
want=$(awk '/^name = "wasm-bindgen"$/{getline; gsub(/version = |"/,""); print; exit}' Cargo.lock 2>/dev/null || true)
if [ -n "$want" ]; then
  have=$(wasm-bindgen --version 2>/dev/null | awk '{print $2}' || true)
  if [ "$have" != "$want" ]; then
    echo "setup: installing wasm-bindgen-cli $want (found '${have:-none}')"
    cargo install -q wasm-bindgen-cli --version "$want" --force
  fi
fi

if [ "$mode" = --web ]; then echo "setup: ok (web)"; exit 0; fi

# npm packages of web/ (package-lock.json): playwright-core and axe-core for the page test, gltf-validator for the
# export tests.
if [ ! -d web/node_modules/playwright-core ] || [ ! -d web/node_modules/gltf-validator ] || [ ! -d web/node_modules/axe-core ]; then
  echo "setup: installing web/ npm packages"
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
fi

# MuJoCo and PyBullet for tests/sim/check_urdf.py, pinned, in a venv under the git-ignored target/.
pyenv=target/pyenv
pins=(mujoco==4.0.0 pybullet==3.2.7)
pins_ok() {
  "$pyenv/bin/python" - "${pins[@]}" >/dev/null 2>&1 <<'PY'
import sys, importlib.metadata as md
import mujoco, pybullet  # noqa: F401  (imports must work, not just the metadata)
sys.exit(any(md.version(n) != v for n, v in (p.split("==") for p in sys.argv[1:])))
PY
}
if ! pins_ok; then
  echo "setup: installing ${pins[*]} into $pyenv"
  "$pyenv/bin/python" -c '' >/dev/null 2>&1 || python3 -m venv --clear "$pyenv"
  "$pyenv/bin/python" -m pip install -q --disable-pip-version-check "${pins[@]}"
  pins_ok || { echo "setup: $pyenv cannot import mujoco and pybullet" >&2; exit 1; }
fi
echo "setup: ok"
