#!/usr/bin/env bash
# Build the documentation site into docs/_build/html: warnings are errors (-W), every
# cross-reference must resolve (-n, nitpicky), every gallery script in examples/ runs. The
# examples of the site's pages run in the tests (tests/test_docs.py). No network is needed.
#
#   bash scripts/docs.sh                  # with python3 on PATH, aerocontrol and .[docs] installed
#   PYTHON=.venv/bin/python bash scripts/docs.sh
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
python=${PYTHON:-python3}
out="$root/docs/_build/html"
rm -rf "$out" "$root/docs/gallery"
MPLBACKEND=Agg "$python" -m sphinx -W --keep-going -n -q -b html "$root/docs" "$out"
echo "documentation: $out/index.html"
