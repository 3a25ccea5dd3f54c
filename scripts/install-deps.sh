#!/bin/sh
# Install the Debian 12 packages rktsph needs to build, test and plot (run as root).
set -eu
PACKAGES="build-essential cmake git pkg-config libeigen3-dev libtomlplusplus-dev libcli11-dev \
libfmt-dev nlohmann-json3-dev libmuparser-dev libhdf5-dev libgtest-dev libgmock-dev libbenchmark-dev \
python3 python3-matplotlib python3-meshio python3-numpy"
missing=""
for p in $PACKAGES; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done
if [ -n "$missing" ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "error: missing packages:$missing; run this script as root (or with sudo)" >&2
    exit 1
  fi
  echo "installing:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing
fi
