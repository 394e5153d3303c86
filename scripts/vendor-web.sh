#!/bin/sh
# The web page's JavaScript libraries, from npm at the versions web/package-lock.json pins, copied
# into web/www/vendor/ (committed: the board serves them as they are, no build step, no network).
# Run after changing web/package.json; `git diff web/www/vendor` shows what changed.
set -eu
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp web/package.json web/package-lock.json "$tmp/"
npm ci --prefix "$tmp" --no-audit --no-fund --loglevel=error
three="$tmp/node_modules/three"
dest=web/www/vendor/three
rm -rf "$dest"
mkdir -p "$dest/build" "$dest/examples/jsm/controls" "$dest/examples/jsm/loaders" "$dest/examples/jsm/utils"
cp "$three/LICENSE" "$dest/"
cp "$three/build/three.module.min.js" "$dest/build/"
cp "$three/examples/jsm/controls/OrbitControls.js" "$dest/examples/jsm/controls/"
cp "$three/examples/jsm/loaders/GLTFLoader.js" "$three/examples/jsm/loaders/PLYLoader.js" "$dest/examples/jsm/loaders/"
cp "$three/examples/jsm/utils/BufferGeometryUtils.js" "$dest/examples/jsm/utils/"
echo "three $(sed -n 's/^ *"version": "\(.*\)",/\1/p' "$three/package.json" | head -n 1) -> $dest"
