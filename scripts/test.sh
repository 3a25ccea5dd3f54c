#!/bin/sh
# README command 2: install the packages, build, and run every test (unit tests, whole-solver
# tests and the quick validation of the thesis cases) with CTest.
set -eu
cd "$(dirname "$0")/.."
sh scripts/install-deps.sh
sh scripts/build.sh
cd build
ctest --output-on-failure -j "$(nproc)" --timeout 1500
