#!/usr/bin/env bash
# The README's main-job command. Today: generates the built-in default object (a procedural
# StorageFurniture cabinet with three drawers and two doors, seed 4), captures it as a two-state RGB-D dataset
# with part maps and ground truth, checks the dataset with `artmesh info`, scores the ground truth
# against itself with `artmesh eval` (all zeros), runs the GPU self-test, and runs the differentiable
# rasterizer's learning driver (`artmesh learn`: a jittered grey copy of a procedural box fitted to 8 views
# at 64x64, printing the loss and PSNR as it goes). The full fit joins once the reconstruction and
# articulation phases land. Usage: scripts/demo.sh [OUTPUT_DIR]
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
target/release/artmesh learn --size 64 --views 8 --iterations 150 > "$out.learn.json"
grep -E '"psnr_(start|end)"' "$out.learn.json"
echo "dataset in $out (object as URDF in $out/object); learning curve in $out.learn.json"
