#!/usr/bin/env bash
# Opens a reproduction report in headless Chromium and saves a full-page screenshot, to look
# at what a reader sees (Debian: apt-get install chromium).
#
#   cargo run --release -- reproduce --out report/
#   tools/screenshot_report.sh report/report.html report.png [width]
set -euo pipefail
html="$(realpath "${1:?report.html}")"
png="${2:-report.png}"
width="${3:-1400}"
browser="$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)"
if [ -z "$browser" ]; then
  echo "error: no chromium found (Debian: apt-get install chromium)" >&2
  exit 1
fi
# A tall window: the screenshot is of the window, so make it hold the whole report.
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
  --window-size="${width},16000" --screenshot="$png" "file://$html" 2>/dev/null
echo "wrote $png"
