#!/bin/sh
# Installs the Debian 12 packages the scanner builds and tests with (called by make when
# pkg-config cannot find one of them). Needs root, as on the CI machine and a fresh rig.
# With the argument "test" it adds what only the tests use (Open3D reads our PLY files; the
# libcamera backend is compiled and tested without a camera; OpenCV builds the calibration
# program), with
# "node" Node.js and npm (the glTF validator of make test), "bench" what only the benchmarks use (OpenCV to compare with, valgrind), with "blender" Blender
# (make check-blender), with "gpio-chip" the
# virtual machine of tests/gpio_chip.sh, with a target triplet
# (aarch64-linux-gnu) what cross-building for it needs.
set -eu
pkgs="build-essential pkg-config libinih-dev libpng-dev libzstd-dev libjpeg-dev libdrm-dev libcmocka-dev libmodbus-dev libgpiod-dev libseccomp-dev"
# the web interface (scanner-web): native builds only
case "${1:-}" in *-linux-gnu*) ;; *) pkgs="$pkgs libcivetweb-dev libcjson-dev" ;; esac
[ "${1:-}" = "bench" ] && pkgs="$pkgs g++ libopencv-dev libopencv-contrib-dev valgrind libspng-dev libzstd-dev python3-open3d"
[ "${1:-}" = "fuzz" ] && pkgs="$pkgs clang libclang-rt-14-dev"
[ "${1:-}" = "blender" ] && pkgs="blender python3-numpy" # tools/cycles_scan.py: a Recommends, which --no-install-recommends leaves out
# make measure-objects: OpenSCAD makes the mechanical parts of data/objects
[ "${1:-}" = "objects" ] && pkgs="openscad"
# make test-browser: Debian's Chromium, driven by playwright-core (tests/browser)
[ "${1:-}" = "browser" ] && pkgs="chromium"
# Node.js and npm run the Khronos glTF validator (tests/gltf); a machine that has them from
# elsewhere (NodeSource's nodejs carries its own npm, which Debian's npm conflicts with) keeps them.
if [ "${1:-}" = "node" ]; then
    command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 && exit 0
    pkgs="nodejs npm"
fi
[ "${1:-}" = "gpio-chip" ] && pkgs="qemu-system-arm cpio systemd socat python3"
[ "${1:-}" = "test" ] && pkgs="$pkgs python3 python3-numpy python3-open3d python3-pymodbus python3-serial python3-serial-asyncio socat g++ clang-format libcamera-dev libopencv-dev libopencv-contrib-dev systemd valgrind"
# A cross build's target (make CROSS_COMPILE=aarch64-linux-gnu-): its compiler, its -dev
# packages through Debian's multiarch, and qemu-user to run its tests.
case "${1:-}" in
*-linux-gnu*)
    arch=$(dpkg-architecture -t "$1" -q DEB_HOST_ARCH 2>/dev/null || echo arm64)
    pkgs="pkg-config gcc-$1 binutils-$1 qemu-user"
    for p in libinih-dev libpng-dev libzstd-dev libjpeg-dev libdrm-dev libcmocka-dev libmodbus-dev libgpiod-dev libseccomp-dev; do
        pkgs="$pkgs $p:$arch"
    done
    if ! dpkg --print-foreign-architectures | grep -qx "$arch"; then
        [ "$(id -u)" -eq 0 ] && dpkg --add-architecture "$arch" || sudo dpkg --add-architecture "$arch"
    fi
    ;;
esac
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
