#!/usr/bin/env bash
# The one test command: builds aerocontrol from scratch into a fresh virtual environment, then
# runs the Rust tests (cargo test) and the Python tests (pytest). Fails if either fails, if no
# test ran, or if the package does not build as one abi3 wheel.
#
#   bash scripts/test.sh            # from anywhere; uses python3 on PATH
#   PYTHON=python3.12 bash scripts/test.sh
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
python=${PYTHON:-python3}
venv="$root/.venv-test"

echo "== fresh virtual environment: $venv"
rm -rf "$venv"
"$python" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade pip

echo "== build and install aerocontrol with its test dependencies"
"$venv/bin/python" -m pip install --quiet ".[test]"

echo "== one abi3 wheel"
rm -rf "$root/dist"
"$venv/bin/python" -m pip wheel --quiet --no-deps --wheel-dir "$root/dist" .
wheels=("$root"/dist/aerocontrol-*.whl)
if [ "${#wheels[@]}" -ne 1 ] || [[ "${wheels[0]}" != *abi3* ]]; then
    echo "expected one abi3 wheel, got: ${wheels[*]}" >&2
    exit 1
fi
echo "${wheels[0]##*/}"

echo "== cargo test"
cargo_log=$(mktemp)
# With the allocator of the Python extension, so the kernels are tested as Python runs them.
cargo test --release --features small-block-allocator 2>&1 | tee "$cargo_log"
cargo_passed=$(grep -Eo 'test result: ok\. [0-9]+ passed' "$cargo_log" | awk '{s += $4} END {print s + 0}')
rm -f "$cargo_log"
if [ "$cargo_passed" -eq 0 ]; then
    echo "cargo test ran no test" >&2
    exit 1
fi

echo "== pytest"
# Run from outside the source tree so that the installed package, not python/, is tested.
(cd "$root/tests" && "$venv/bin/python" -m pytest -p no:cacheprovider "$root/tests")

echo "== all tests passed (cargo: $cargo_passed)"
