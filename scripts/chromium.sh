#!/usr/bin/env bash
# Prints the command of the Chromium installed here (chromium,
# chromium-browser or google-chrome), or exits 1 saying none is: the
# browser scripts/screenshot.sh and tests/cli/report-layout.sh open
# reports in (apt-get install chromium).
for b in chromium chromium-browser google-chrome; do
	if command -v "$b" >/dev/null 2>&1; then
		echo "$b"
		exit 0
	fi
done
echo "no chromium installed (apt-get install chromium)" >&2
exit 1
