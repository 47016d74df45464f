#!/usr/bin/env bash
# Opens a report in a real browser (headless Chromium) and saves a
# screenshot, to see the summary table and the charts as a reader does.
# Usage: scripts/screenshot.sh [REPORT.html] [OUT.png]
#   default: results/default/report.html -> results/default/report.png
#   SCREENSHOT_HEIGHT=6000 takes more of a long page (default 2000 px).
# Exits 0 without a screenshot (and says so) when chromium is not installed:
# it is an optional check, not a dependency (apt-get install chromium).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

case "${1:-}" in
-h|--help)
	sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
	exit 0
	;;
esac

report=${1:-$root/results/default/report.html}
out=${2:-${report%.html}.png}
[ -f "$report" ] || { echo "screenshot.sh: no report at $report (run scripts/run.sh first)" >&2; exit 2; }

if ! browser=$("$root/scripts/chromium.sh" 2>/dev/null); then
	echo "screenshot.sh: no chromium installed; skipped (apt-get install chromium)" >&2
	exit 0
fi

abs=$(cd "$(dirname "$report")" && pwd)/$(basename "$report")
# A private profile folder: no first-run state, nothing left behind.
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
# --no-sandbox: root in a container has no user namespaces for the sandbox.
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
	--user-data-dir="$profile" --window-size=1400,"${SCREENSHOT_HEIGHT:-2000}" \
	--screenshot="$out" "file://$abs" >/dev/null 2>&1
[ -s "$out" ] || { echo "screenshot.sh: $browser wrote no screenshot" >&2; exit 1; }
echo "screenshot.sh: $out"
