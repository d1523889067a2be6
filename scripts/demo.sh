#!/usr/bin/env bash
# The README's main-job command. Today: generates the built-in default object (a procedural
# StorageFurniture cabinet with three drawers and two doors, seed 4), captures it as a two-state RGB-D dataset
# with part maps and ground truth, checks the dataset with `artmesh info`, scores the ground truth
# against itself with `artmesh eval` (all zeros), runs the GPU self-test, and runs the reconstruction
# phase on it (`artmesh reconstruct --preset fast`: per state a part-aware mesh from 12 views at 57x57,
# with a progress bar, writing one PLY per part and state and a quality report with Chamfer to the
# ground truth). The articulation phase joins with its issue. Usage: scripts/demo.sh [OUTPUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --native
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/artmesh-xdg-$(id -u)}
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
cargo build --release --bin artmesh
out=${1:-$(mktemp -d "${TMPDIR:-/tmp}/artmesh-demo.XXXXXX")/cabinet}
target/release/artmesh synth --category storage --parts 5 --seed 4 --out "$out" \
    --width 400 --height 400 --train-views 40 --test-views 8
target/release/artmesh info "$out"
target/release/artmesh eval "$out" "$out" --samples 2000 | grep -E '"(axis_ang|axis_pos|part_motion)"' | sort | uniq -c
target/release/artmesh gpu
target/release/artmesh reconstruct "$out" --out "$out.reconstruction" --preset fast > /dev/null
echo "dataset in $out (object as URDF in $out/object); part meshes and report.json in $out.reconstruction"
