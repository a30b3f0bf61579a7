#!/usr/bin/env bash
# The one test command: builds aerocontrol from scratch into a fresh virtual environment, then
# runs the style and type checks and the tests. Fails on the first failure, if no test ran, or
# if the package does not build as one abi3 wheel.
#
#   bash scripts/test.sh            # from anywhere; uses python3 on PATH
#   PYTHON=python3.12 bash scripts/test.sh
#
# Steps: a fresh venv; one abi3 wheel, installed with the test and docs dependencies; cargo fmt
# --check, ruff check, ruff format --check; cargo clippy --all-targets -D warnings
# (with the Python bindings); cargo test without features (as the README's cargo test, with the
# allocator's unit tests); pytest (which also runs mypy --strict and stubtest on the package,
# the doctests, and the property suite within its CI budget); the documentation site
# (scripts/docs.sh).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
python=${PYTHON:-python3}
venv="$root/.venv-test"

echo "== fresh virtual environment: $venv"
rm -rf "$venv"
"$python" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade pip

echo "== build one abi3 wheel, and install it with the test and documentation dependencies"
rm -rf "$root/dist"
"$venv/bin/python" -m pip wheel --quiet --no-deps --wheel-dir "$root/dist" .
wheels=("$root"/dist/aerocontrol-*.whl)
if [ "${#wheels[@]}" -ne 1 ] || [[ "${wheels[0]}" != *abi3* ]]; then
    echo "expected one abi3 wheel, got: ${wheels[*]}" >&2
    exit 1
fi
echo "${wheels[0]##*/}"
"$venv/bin/python" -m pip install --quiet "${wheels[0]}[test,docs]"

echo "== style: cargo fmt, ruff"
cargo fmt --all --check
"$venv/bin/ruff" check python tests benches scripts examples docs
"$venv/bin/ruff" format --check python tests benches scripts examples docs

echo "== cargo clippy"
# PYO3_PYTHON: the bindings' build script needs an interpreter.
PYO3_PYTHON="$venv/bin/python" cargo clippy --release --features python --all-targets -- -D warnings

cargo_passed=0
run_cargo_test() {
    local log
    log=$(mktemp)
    cargo test --release "$@" 2>&1 | tee "$log"
    cargo_passed=$((cargo_passed + $(grep -Eo 'test result: ok\. [0-9]+ passed' "$log" | awk '{s += $4} END {print s + 0}')))
    rm -f "$log"
}
# One run, as a Rust user runs it: the allocator's own tests are in it, and pytest runs every
# kernel under that allocator through the extension.
echo "== cargo test"
run_cargo_test
if [ "$cargo_passed" -eq 0 ]; then
    echo "cargo test ran no test" >&2
    exit 1
fi

echo "== pytest"
# Run from outside the source tree so that the installed package, not python/, is tested.
(cd "$root/tests" && "$venv/bin/python" -m pytest -p no:cacheprovider "$root/tests")

echo "== documentation site (warnings are errors, every reference resolves, the gallery runs)"
PYTHON="$venv/bin/python" bash "$root/scripts/docs.sh"

echo "== all checks and tests passed (cargo: $cargo_passed)"
