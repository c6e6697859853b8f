#!/usr/bin/env bash
# Python peers of the mesh-sampling benchmark: trimesh's sample_surface and
# Open3D's sample_points_uniformly, timed by peers.py (next to this file).
#
#   bash mesh-sampling/bench/peers.sh MESH.obj N REPEATS
#   PEER_SCRIPT=blue_noise_peer.py bash mesh-sampling/bench/peers.sh ARGS...
#
# stdout carries only the results, one JSON object per peer and line (the
# Rust benchmark parses it); all set-up chatter goes to stderr. The first
# run creates a venv at ${CARGO_TARGET_DIR:-<workspace>/target}/peers-venv
# and pip-installs numpy, trimesh and open3d-cpu into it (20 s to minutes),
# and pymeshlab for blue_noise_peer.py (MeshLab's Poisson-disk sampling);
# later runs only check the imports. Open3D's wheel needs the system library
# libusb-1.0-0, which is apt-get installed if missing. A peer that cannot be
# installed is reported as {"peer": "...", "error": "..."} by peers.py, and
# the other one still runs.
set -u
script="${PEER_SCRIPT:-peers.py}" # another peer script in this folder
[ "$script" != peers.py ] || [ $# -eq 3 ] || { echo "usage: $0 MESH.obj N REPEATS" >&2; exit 2; }
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
venv="${CARGO_TARGET_DIR:-$(cd "$here/../.." && pwd)/target}/peers-venv"
py="$venv/bin/python"
exec 3>&1 1>&2 # from here on stdout goes to stderr; fd 3 is the real stdout
say() { echo "peers.sh: $*"; }

if [ ! -x "$venv/bin/pip" ]; then
    say "creating the venv $venv"
    if ! "${PYTHON:-python3}" -m venv "$venv"; then
        for peer in trimesh open3d; do
            echo "{\"peer\": \"$peer\", \"error\": \"cannot create the venv $venv\"}" >&3
        done
        exit 1
    fi
fi
pip_install() { say "pip install $*"; "$py" -m pip install --quiet "$@"; }

"$py" -c 'import numpy, trimesh' 2>/dev/null ||
    pip_install numpy trimesh || say "could not install trimesh"

o3d_libusb() { [[ $("$py" -c 'import open3d' 2>&1) == *libusb* ]]; }
if ! "$py" -c 'import open3d' 2>/dev/null; then
    o3d_libusb || pip_install open3d-cpu || say "could not install open3d-cpu"
    if o3d_libusb; then
        say "Open3D needs libusb-1.0-0: apt-get install -y libusb-1.0-0"
        sudo=""
        [ "$(id -u)" -ne 0 ] && command -v sudo >/dev/null && sudo=sudo
        export DEBIAN_FRONTEND=noninteractive
        $sudo apt-get install -y -q libusb-1.0-0 ||
            { $sudo apt-get update -q && $sudo apt-get install -y -q libusb-1.0-0; } ||
            say "could not install libusb-1.0-0"
    fi
fi

if [ "$script" = blue_noise_peer.py ] && ! "$py" -c 'import pymeshlab' 2>/dev/null; then
    pip_install pymeshlab || say "could not install pymeshlab"
fi
if [ "$script" = blue_noise_peer.py ] && ! "$py" -c 'import point_cloud_utils' 2>/dev/null; then
    pip_install point-cloud-utils || say "could not install point-cloud-utils"
fi

exec "$py" "$here/$script" "$@" 1>&3 3>&-
