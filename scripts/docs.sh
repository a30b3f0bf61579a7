#!/usr/bin/env bash
# Build the documentation site into docs/_build/html: warnings are errors (-W), every
# cross-reference must resolve (-n, nitpicky), every gallery script in examples/ runs. The
# examples of the site's pages run in the tests (tests/test_docs.py). No network is needed
# beyond the package index for the first install.
#
#   bash scripts/docs.sh                          # from a fresh clone: installs aerocontrol
#                                                 # with .[docs] into .venv-docs, then builds
#   PYTHON=.venv/bin/python bash scripts/docs.sh  # with an environment that has both already
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [ -z "${PYTHON:-}" ]; then
    venv="$root/.venv-docs"
    if [ ! -x "$venv/bin/python" ]; then
        python3 -m venv "$venv"
        "$venv/bin/python" -m pip install --quiet --upgrade pip
    fi
    echo "== install aerocontrol with the documentation dependencies into $venv"
    "$venv/bin/python" -m pip install --quiet "$root[docs]"
    PYTHON="$venv/bin/python"
fi
out="$root/docs/_build/html"
rm -rf "$out" "$root/docs/gallery"
MPLBACKEND=Agg "$PYTHON" -m sphinx -W --keep-going -n -q -b html "$root/docs" "$out"
echo "documentation: $out/index.html"
