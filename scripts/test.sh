#!/usr/bin/env bash
# The project's one test command (README; .ci/run calls exactly this). On a fresh Debian machine
# with only rustup it installs what it needs (scripts/setup.sh: apt packages, the wasm target,
# wasm-bindgen-cli, web/'s npm packages, a venv with MuJoCo and PyBullet), then runs: formatting,
# clippy for both targets, native tests on the Vulkan backend (lavapipe when no GPU), the wasm build,
# the wasm-bindgen browser tests and the page's end-to-end test in headless Chromium (WebGPU).
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s (at %d s)\n' "$*" "$SECONDS"; }

step "setup"
scripts/setup.sh

# wgpu silently falls back to GL without this when no Vulkan driver is found.
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
# Silences harmless lavapipe warnings about a missing runtime dir.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/artmesh-xdg-$(id -u)}
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"

step "format"
cargo fmt --check

step "clippy (native and wasm32)"
cargo clippy --all-targets -q -- -D warnings
cargo clippy --lib --tests --target wasm32-unknown-unknown -q -- -D warnings

step "native tests (WGPU_BACKEND=$WGPU_BACKEND)"
cargo test --all-targets

step "wasm build of the page"
# The dev profile shares its build with the browser tests below (a release build would compile
# wgpu for wasm a second time); `web/build.sh` alone builds release for people.
# It is written as the static folder a host would get (--dist), and the page test below serves that.
rm -rf target/web-dist
ARTMESH_WEB_PROFILE=dev web/build.sh --dist target/web-dist

step "browser tests (wasm-bindgen-test in headless Chromium, WebGPU)"
export CHROMEDRIVER=${CHROMEDRIVER:-/usr/bin/chromedriver}
export WASM_BINDGEN_TEST_TIMEOUT=${WASM_BINDGEN_TEST_TIMEOUT:-900}
cargo test --target wasm32-unknown-unknown --test web

step "page end-to-end test (playwright-core + Debian Chromium, serving target/web-dist)"
# The README's web command runs beside it, as a fresh clone would run it; the test opens that page too.
serve_port=${ARTMESH_SERVE_PORT:-8765}
ARTMESH_WEB_PROFILE=dev web/build.sh --serve "$serve_port" > target/web-serve.log 2>&1 &
serve_pid=$!
trap 'kill "$serve_pid" 2>/dev/null || true' EXIT
(cd web && ARTMESH_WEB_ROOT=../target/web-dist ARTMESH_SERVE_URL="http://127.0.0.1:$serve_port/" node test/page.mjs)

step "all tests passed"
