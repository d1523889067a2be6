#!/usr/bin/env bash
# The README's main-job command. Today: writes the built-in sample object (a synthetic two-state
# dataset with depth, part maps and ground-truth joints), checks it with `artmesh info`, and runs
# the GPU self-test on this machine's adapter. The fit itself joins once the reconstruction and
# articulation phases land. Usage: scripts/demo.sh [OUTPUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --native
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/artmesh-xdg-$(id -u)}
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
cargo build --release --bin artmesh
out=${1:-$(mktemp -d "${TMPDIR:-/tmp}/artmesh-demo.XXXXXX")/sample}
target/release/artmesh sample --out "$out"
target/release/artmesh info "$out"
target/release/artmesh gpu
