#!/usr/bin/env bash
# A long property campaign: every property of tests/properties with EXAMPLES random examples
# each (default 1000), then the tally as a Markdown table (function, cases, outcomes by class).
# Fails if any property fails.
#
#   bash scripts/fuzz.sh 300                 # with the python3 on PATH (aerocontrol installed)
#   PYTHON=.venv/bin/python bash scripts/fuzz.sh 2000
#
# The hypothesis example database lives in a temporary folder (AEROCONTROL_FUZZ_DATABASE to
# keep one); the JSON tally is kept in AEROCONTROL_FUZZ_REPORT if set.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
python=${PYTHON:-python3}
examples=${1:-1000}
if ! [[ "$examples" =~ ^[1-9][0-9]*$ ]]; then
    echo "usage: bash scripts/fuzz.sh [EXAMPLES], EXAMPLES a positive integer" >&2
    exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
report=${AEROCONTROL_FUZZ_REPORT:-$work/tally.json}
database=${AEROCONTROL_FUZZ_DATABASE:-$work/examples}

status=0
# From outside the source tree, so that the installed package is what is tested.
(cd "$work" && AEROCONTROL_FUZZ_EXAMPLES=$examples AEROCONTROL_FUZZ_REPORT=$report \
    AEROCONTROL_FUZZ_DATABASE=$database \
    "$python" -m pytest -p no:cacheprovider -q "$root/tests/properties") || status=$?
"$python" "$root/scripts/fuzz_table.py" "$report"
exit "$status"
