#!/usr/bin/env bash
# The meshopt-compressed test files of crates/alhazen-import/tests/data/gltfpack, made by gltfpack
# (meshoptimizer's glTF packer, `npm install gltfpack`; version 1.3 made the committed ones) from
# two of Blender's exports of the Cycles comparisons (tests/data/blender): the painted panel
# (positions, normals, colours) and the seven GPU instances of a cone (instance transforms).
# For each, three files: `-plain` quantised (KHR_mesh_quantization) but not compressed, `-ext`
# compressed (`-c`: EXT_meshopt_compression, attribute codec version 0, no filters for the
# panel; the instances' translations, rotations and scales through the exponential and
# quaternion filters, its normals octahedral), `-khr` compressed harder (`-cc -ce khr`:
# KHR_meshopt_compression, attribute codec version 1, octahedral normals, YCoCg colours).
#
#     bench/gltfpack/make.sh OUT_DIR [GLTFPACK]
set -euo pipefail
out=$1
gltfpack=${2:-gltfpack}
data="$(dirname "$0")/../../crates/alhazen-import/tests/data/blender"
mkdir -p "$out"
"$gltfpack" -i "$data/vertex-colors.glb" -o "$out/vertex-colors-plain.glb"
"$gltfpack" -c -i "$data/vertex-colors.glb" -o "$out/vertex-colors-ext.glb"
"$gltfpack" -cc -ce khr -i "$data/vertex-colors.glb" -o "$out/vertex-colors-khr.glb"
"$gltfpack" -mi -i "$data/instances.glb" -o "$out/instances-plain.glb"
"$gltfpack" -cc -mi -i "$data/instances.glb" -o "$out/instances-ext.glb"
"$gltfpack" -cc -mi -ce khr -i "$data/instances.glb" -o "$out/instances-khr.glb"
