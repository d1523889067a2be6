#!/usr/bin/env bash
# Builds the page's wasm module into web/pkg (wasm-bindgen --target web); with --serve, then
# serves web/ on http://127.0.0.1:8000/. The built page is static files only.
set -euo pipefail
cd "$(dirname "$0")/.."
profile=${ARTMESH_WEB_PROFILE:-release}
cargo build --lib --target wasm32-unknown-unknown --profile "$profile"
dir=$([ "$profile" = dev ] && echo debug || echo "$profile")
wasm-bindgen --target web --no-typescript --out-dir web/pkg "target/wasm32-unknown-unknown/$dir/artmesh.wasm"
echo "web: built web/pkg ($(du -h web/pkg/artmesh_bg.wasm | cut -f1) wasm)"
if [ "${1:-}" = "--serve" ]; then
  exec node web/serve.mjs "${2:-8000}"
fi
