#!/bin/sh
# MeshLab (Debian 12: 2020.09, headless under Xvfb) opens the fused mesh of a scan directory with
# every vertex and face. Not in `make test` (MeshLab and Xvfb are a large install); run it with
# `make interop-meshlab`. MeshLab 2020.09 as packaged aborts on any OBJ file (Debian bug
# #1054006), so only mesh.ply is checked here; Open3D reads mesh.obj in make test.
set -eu
dir=$1
command -v meshlabserver >/dev/null && command -v xvfb-run >/dev/null || {
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
        --no-install-recommends meshlab xvfb xauth >/dev/null
}
out=$(mktemp -d)
log=$(timeout 300 xvfb-run -a meshlabserver -i "$dir/mesh.ply" -o "$out/copy.ply" -m vc vn 2>&1)
want=$(sed -n 's/^element vertex \([0-9]*\)/\1 vn/p; s/^element face \([0-9]*\)/\1 fn/p' "$dir/mesh.ply" |
    tr '\n' ' ' | sed 's/ $//')
echo "$log" | grep "saved as" || { echo "$log"; exit 1; }
echo "$log" | grep -q "($want)" || { echo "meshlab: expected ($want)"; exit 1; }
echo "meshlab opened $dir/mesh.ply: $want"
rm -rf "$out"
