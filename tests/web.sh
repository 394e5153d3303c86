#!/bin/sh
# scanner serve against a hostile tester (tests/web_hostile.py): cmocka-style lines for
# tests/run.sh. The web server is built wherever make builds it (libcivetweb-dev, libcjson-dev).
set -u
cd "$(dirname "$0")/.."
if [ ! -x "${BUILD:-build}/scanner-web" ]; then
    echo "[  FAILED  ] ${BUILD:-build}/scanner-web is not built (make installs libcivetweb-dev)"
    echo "[  FAILED  ] 1 test(s)."
    exit 1
fi
exec /usr/bin/python3 tests/web_hostile.py "${BUILD:-build}"
