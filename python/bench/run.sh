#!/usr/bin/env bash
# The Python benchmark: builds the trilux wheel (release), installs it with
# numpy and trimesh in a venv under target/, tries each peer library
# (Open3D, point-cloud-utils, pymeshlab, pytetwild, tetgen) on its own so that one
# that will not install is skipped (bench.py says so), then prints the
# Markdown tables of bench.py. Usage, from the workspace root:
#
#     TRILUX_DATA=../shared/data bash python/bench/run.sh [--repeats 5] [--quick]
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV=target/py-bench-venv
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip
"$VENV/bin/python" -m pip install -q "maturin>=1.9.4,<2" numpy scipy pillow trimesh
# Open3D's wheel links libusb, which a bare Debian lacks; pytetwild
# imports pyvista without declaring it.
if ! ldconfig -p | grep -q libusb-1.0.so.0 && command -v apt-get >/dev/null; then
  (apt-get update -qq && apt-get install -y -qq --no-install-recommends libusb-1.0-0 >/dev/null) ||
    echo "note: libusb-1.0-0 did not install; Open3D's rows will be skipped" >&2
fi
for peer in open3d point-cloud-utils pymeshlab pytetwild pyvista tetgen; do
  "$VENV/bin/python" -m pip install -q "$peer" >/dev/null 2>&1 || echo "note: $peer did not install; its rows are skipped" >&2
done
rm -rf target/py-bench-wheels
"$VENV/bin/maturin" build -q --release -m python/Cargo.toml -i "$VENV/bin/python" --out target/py-bench-wheels
"$VENV/bin/python" -m pip install -q --force-reinstall --no-deps target/py-bench-wheels/trilux-*.whl
exec "$VENV/bin/python" python/bench/bench.py "$@"
