#!/bin/sh
# Regenerates the example input files of the user guide (examples/README.md
# says what each is). Seeded: the same build writes the same files.
#
#   examples/make.sh          # from anywhere; needs cargo and python3
#   SPHERECAL=target/release/spherecal examples/make.sh   # a binary already built
set -eu
cd "$(dirname "$0")/.."
if [ -z "${SPHERECAL:-}" ]; then
  cargo build --quiet
  SPHERECAL=target/debug/spherecal
fi
spherecal() { "$SPHERECAL" "$@"; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rm -rf examples/scan examples/artefact examples/poses examples/log
rm -f examples/targets.csv examples/targets-matrix.txt examples/path.mod

# Raw scans taken with the seed-7 cell: a stepped block (10 poses) and a
# three-sphere artefact (5 poses a sphere), each with the truth of the part.
spherecal simulate --seed 7 --scan steps --scan-poses 10 \
  --csv-out examples/scan --out examples/scan/truth.json -q
spherecal simulate --seed 7 --scan spheres --scan-poses 5 \
  --csv-out examples/artefact --out examples/artefact/truth.json -q

# What convert.py needs: the seed-7 cell's result (its hand-eye places the
# targets) and a small cell's joint log and profiles.
spherecal simulate --seed 7 --out "$tmp/cell.json" -q
spherecal calibrate "$tmp/cell.json" --out "$tmp/cell.result.json" -q
spherecal simulate --seed 4 --identify-stations 3 --validate-stations 2 --poses 4 \
  --csv-out "$tmp/log" --out "$tmp/log.json" -q
python3 examples/convert.py "$tmp"
