#!/usr/bin/env bash
# Install the Debian libraries the gmsh and VTK wheels load at import time, if missing.
set -euo pipefail
need=()
for pkg in libgl1 libglu1-mesa libxrender1 libxcursor1 libxft2 libxinerama1 libgomp1; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -eq 0 ]; then exit 0; fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "tmfem: missing system libraries ${need[*]} and no apt-get; install them by hand" >&2
  exit 1
fi
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "tmfem: installing system libraries: ${need[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
