#!/usr/bin/env bash
# The README's main-job command: `artmesh demo` on the built-in default object (a procedural
# StorageFurniture cabinet with a drawer and a door, seed 4). It captures the object as a two-state
# RGB-D dataset with part maps and ground truth (256x256, 12 train + 4 test views per state), fits it with the `fast`
# preset (reconstruction of both states, part-aware remeshing, articulation with the joint-type
# bake-off), scores it against the ground truth and writes dataset, joints.json, part meshes and
# report.json to a new folder. Usage: scripts/demo.sh [OUTPUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --native
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/artmesh-xdg-$(id -u)}
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
cargo build --release --bin artmesh
out=${1:-$(mktemp -d "${TMPDIR:-/tmp}/artmesh-demo.XXXXXX")/demo}
target/release/artmesh demo --out "$out" > "$out.report.json"
echo "dataset in $out/dataset; joints.json, part meshes and report.json in $out/fit; the printed report in $out.report.json"
