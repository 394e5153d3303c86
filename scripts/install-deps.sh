#!/bin/sh
# Installs the Debian 12 packages the scanner builds and tests with (called by make when
# pkg-config cannot find one of them). Needs root, as on the CI machine and a fresh rig.
# With the argument "test" it adds what only the tests use (Open3D reads our PLY files), with
# "bench" what only the benchmarks use (OpenCV to compare with, valgrind).
set -eu
pkgs="build-essential pkg-config libinih-dev libpng-dev libcmocka-dev libmodbus-dev libgpiod-dev"
[ "${1:-}" = "bench" ] && pkgs="$pkgs g++ libopencv-dev libopencv-contrib-dev valgrind"
[ "${1:-}" = "test" ] && pkgs="$pkgs python3 python3-numpy python3-open3d python3-pymodbus python3-serial python3-serial-asyncio socat"
missing=""
for p in $pkgs; do
    dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "install-deps: installing$missing"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
