#!/bin/sh
# README command 1: install the packages, build, run the default case (thesis case 1, the 1D
# elastic bar) end to end and plot its probes.
set -eu
cd "$(dirname "$0")/.."
sh scripts/install-deps.sh
sh scripts/build.sh
./build/rktsph run cases/thesis/01_elastic_bar_1d.toml --out out/01_elastic_bar_1d
/usr/bin/python3 scripts/plot_probes.py out/01_elastic_bar_1d
echo "done: open out/01_elastic_bar_1d/nodes.pvd in ParaView; plot: out/01_elastic_bar_1d/probes.png"
