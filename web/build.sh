#!/usr/bin/env bash
# Builds the page's wasm module into web/pkg (wasm-bindgen --target web), first installing what
# that needs (scripts/setup.sh --web: the wasm target, wasm-bindgen-cli, Node.js). Then:
#   web/build.sh                 only the build
#   web/build.sh --serve [PORT]  serves web/ on http://127.0.0.1:PORT/ (default 8000)
#   web/build.sh --dist OUT      writes the page as a self-contained static folder OUT (index.html,
#                                ES modules, style, wasm; nothing from node_modules) for any static
#                                host, and checks the wasm's gzipped size against the budget
# ARTMESH_WEB_PROFILE=dev builds the quicker debug module (the size budget is then only reported).
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { echo "usage: web/build.sh [--serve [PORT] | --dist OUT]" >&2; exit 2; }
action=build target=""
case "${1:-}" in
  "") ;;
  --serve) action=serve target=${2:-8000} ;;
  --dist) action=dist target=${2:-}; [ -n "$target" ] || usage ;;
  *) usage ;;
esac
if [ "$action" = dist ] && [ -e "$target" ] && [ -n "$(ls -A "$target" 2>/dev/null || echo x)" ]; then
  # Never replace what is there: a dist goes to a new or empty folder.
  echo "web: $target exists and is not an empty folder; choose a new folder for --dist" >&2
  exit 1
fi

scripts/setup.sh --web
profile=${ARTMESH_WEB_PROFILE:-release}
cargo build --lib --target wasm32-unknown-unknown --profile "$profile"
dir=$([ "$profile" = dev ] && echo debug || echo "$profile")
wasm-bindgen --target web --no-typescript --out-dir web/pkg "target/wasm32-unknown-unknown/$dir/artmesh.wasm"
echo "web: built web/pkg ($(du -h web/pkg/artmesh_bg.wasm | cut -f1) wasm)"

case "$action" in
  serve) exec node web/serve.mjs "$target" ;;
  dist) exec node web/dist.mjs "$target" "$profile" ;;
esac
