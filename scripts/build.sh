#!/bin/sh
# Configure and build rktsph (Release) into build/.
set -eu
cd "$(dirname "$0")/.."
# Tuned for the machine it runs on (-march=native); configure without RKTSPH_NATIVE for a
# portable build.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DRKTSPH_NATIVE=ON >/dev/null
cmake --build build -j "$(nproc)"
