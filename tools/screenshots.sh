#!/usr/bin/env bash
# Regenerates the screenshots in assets/ (the README's and the guide's),
# each taken by the real workbench window at 1366×768 under Xvfb:
#
#   bash tools/screenshots.sh                  # every scenario, then report.png
#   bash tools/screenshots.sh results fail     # only these scenarios
#
# Run it again after any change to a view. It builds the debug binary,
# makes the scenarios' input files with the command line in a scratch
# folder (SPHERECAL_SHOTS_DIR, default /tmp/spherecal-screenshots, emptied
# first), then starts `spherecal gui` once per scenario with
# SPHERECAL_SCREENSHOT=<scenario>:<file>: the window drives itself through
# the scenario (src/screenshots/scenarios.rs says what each does), saves its own
# picture and closes. report.png is the HTML report's first screen in
# headless Chromium, taken when Chromium is installed.
#
# Needs (Debian packages; nothing is installed here): xvfb and xauth
# (xvfb-run), chromium for report.png only. About 2 minutes on 2 cores
# once the binary is built.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
cd "$repo"

missing=()
command -v xvfb-run >/dev/null 2>&1 || missing+=(xvfb)
command -v xauth >/dev/null 2>&1 || missing+=(xauth)
if [ ${#missing[@]} -gt 0 ]; then
  echo "error: the screenshots need the Debian package(s) ${missing[*]}:" >&2
  echo "  apt-get install --no-install-recommends ${missing[*]}" >&2
  exit 1
fi

started=$(date +%s)
cargo build --quiet
bin="${CARGO_TARGET_DIR:-$repo/target}/debug/spherecal"
spherecal() { "$bin" "$@"; }

# The scratch folder the window runs in: the repository's data folders
# linked in, the generated inputs beside them.
work="${SPHERECAL_SHOTS_DIR:-/tmp/spherecal-screenshots}"
rm -rf "$work"
mkdir -p "$work"
for d in sessions data examples; do ln -s "$repo/$d" "$work/$d"; done
for f in examples/path.mod examples/artefact/joints.csv data/robcalibrator-sphere/RobPoses.rob; do
  [ -e "$f" ] || { echo "error: $f is missing (examples/make.sh makes the examples)" >&2; exit 1; }
done
(
  cd "$work"
  spherecal simulate --csv-out sim --out sim.json -q
  spherecal simulate --validate-stations 60 --out fig5-60.json -q
  spherecal simulate --validate-stations 3 --seed 3 --out fig6-12.json -q
  spherecal simulate --identify-stations 60 --validate-stations 10 --out centres-70.json -q
  spherecal simulate --identify-stations 3000 --centres --poses 3 --out centres-3000.json -q
  spherecal simulate --seed 7 --out seed7.json -q
  spherecal simulate --mount fixed --seed 4 --out fixed.json -q
  # A sphere knocked by 1.5 mm (in sensor y) at the first identify pose.
  spherecal simulate --centres --name "cell 3, a sphere knocked by 1.5 mm" --out fail.json -q
  awk '
    /"use": "identify"/ && !done { armed = 1 }
    armed && /"centre": \[/ {
      match($0, /\[.*\]/)
      split(substr($0, RSTART + 1, RLENGTH - 2), v, ", ")
      sub(/\[.*\]/, sprintf("[%s, %.4f, %s]", v[1], v[2] + 1.5, v[3]))
      armed = 0; done = 1
    }
    { print }
    END { if (!done) exit 1 }' fail.json > fail.knocked
  mv fail.knocked fail.json
)

# The window's environment: a display scale of 1, Mesa quiet.
export WINIT_X11_SCALE_FACTOR=1
export XDG_RUNTIME_DIR="$work/xdg-runtime"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"

if [ $# -gt 0 ]; then
  wanted=" $* "
else
  wanted=""
fi
failed=()
while read -r name file; do
  [ -z "$wanted" ] || [[ "$wanted" == *" $name "* ]] || continue
  if ! (cd "$work" && SPHERECAL_SCREENSHOT="$name:$repo/assets/$file" \
    xvfb-run -a -s "-screen 0 1366x768x24" "$bin" gui 2> "$work/$name.log"); then
    echo "FAILED: $name (its log: $work/$name.log)" >&2
    tail -n 5 "$work/$name.log" >&2
    failed+=("$name")
  fi
done < <(SPHERECAL_SCREENSHOT=list xvfb-run -a "$bin" gui)

# The HTML report of the demo, its first screen as a browser shows it.
if [ -z "$wanted" ] || [[ "$wanted" == *" report "* ]]; then
  if command -v chromium >/dev/null 2>&1; then
    (
      cd "$work"
      spherecal calibrate sessions/demo-irb2400.json --out demo.result.json -q
      spherecal report sessions/demo-irb2400.json --result demo.result.json \
        --tolerance 0.2,0.5 --out report.html -q
      chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage \
        --no-first-run --hide-scrollbars --force-device-scale-factor=1 \
        --user-data-dir="$work/chromium" --window-size=1366,768 \
        --screenshot="$repo/assets/report.png" "file://$work/report.html" \
        > "$work/chromium.log" 2>&1
    ) && echo "wrote $repo/assets/report.png (headless Chromium)" \
      || { echo "FAILED: report (its log: $work/chromium.log)" >&2; failed+=(report); }
  else
    echo "skipped assets/report.png: no chromium (Debian package chromium)"
  fi
fi

echo "screenshots took $(( $(date +%s) - started )) s"
if [ ${#failed[@]} -gt 0 ]; then
  echo "error: ${#failed[@]} failed: ${failed[*]}" >&2
  exit 1
fi
