#!/usr/bin/env bash
# The luminaire benchmark (Šik & Křivánek 2013, Fig. 1b) with its Mitsuba 3
# peer, as one table:
#
#   bash mesh-sampling/bench/run.sh [luminaire options…]
#
# Builds and runs `cargo run --release -p mesh-sampling --example luminaire`
# on $TRILUX_DATA (../shared/data by default) with `--mitsuba`, so that the
# example runs bench/mitsuba_luminaire.py on the same rectangle and bunny
# and puts Mitsuba's rows in its tables (Markdown on stdout; pictures in
# target/luminaire, and with --pictures DIR the README's PNGs). The load
# average (uptime) is printed first, for the table's heading.
#
# Mitsuba 3 comes from PyPI (`mitsuba`, with numpy) into the venv
# ${CARGO_TARGET_DIR:-<workspace>/target}/peers-venv, created on the first
# run; later runs only check the import. If it cannot be installed, the
# example still runs and says why Mitsuba's rows are missing.
set -u
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
target="${CARGO_TARGET_DIR:-$root/target}"
venv="$target/peers-venv"
py="$venv/bin/python"
say() { echo "run.sh: $*" >&2; }

if [ ! -x "$venv/bin/pip" ]; then
    say "creating the venv $venv"
    "${PYTHON:-python3}" -m venv "$venv" || say "cannot create the venv $venv"
fi
if [ -x "$py" ] && ! "$py" -c 'import mitsuba, numpy' 2>/dev/null; then
    say "pip install mitsuba numpy (into $venv)"
    "$py" -m pip install --quiet mitsuba numpy >&2 || say "could not install mitsuba"
fi
peer=()
if [ -x "$py" ]; then
    peer=(--mitsuba "$py")
fi

export TRILUX_DATA="${TRILUX_DATA:-$root/../shared/data}"
cd "$root" || exit 1
cargo build --release -q -p mesh-sampling --example luminaire || exit 1
# The load goes to stdout with the Markdown tables, to stderr with --json.
load() {
    case " $* " in
    *" --json "*) echo "$label $(uptime)" >&2 ;;
    *) printf '%s %s\n\n' "$label" "$(uptime)" ;;
    esac
}
label="Load before the run (uptime):" load "$@"
"$target/release/examples/luminaire" "${peer[@]}" "$@"
status=$?
label="Load after the run (uptime):" load "$@"
exit $status
