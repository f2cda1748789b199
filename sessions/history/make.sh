#!/bin/sh
# Regenerates the example history library in this folder: five dated,
# simulated calibrations of one ABB IRB 2400/16 (centre sessions and their
# `ml` results), with a sensor remount in April (hand-eye jump) and a
# joint-3 zero change in May (theta3 jump). What each month holds is in
# examples/history_library.rs. Seeded: the same build writes the same files.
#
#   sessions/history/make.sh          # then: spherecal history sessions/history
set -eu
cd "$(dirname "$0")/../.."
rm -f sessions/history/cell3-*.json
cargo run --quiet --no-default-features --example history_library -- sessions/history
