#!/usr/bin/env bash
# report.html at 1400 px in a real browser: a small sweep's report is
# opened in headless Chromium, and a script reads the layout (DOM widths):
# the page must not scroll sideways, and every cell of every table (the
# scene tables' columns above all) must lie inside the window, none
# squeezed to nothing. Skipped (77) with a one-line reason where Chromium
# is not installed (apt-get install chromium).
# Usage: report-layout.sh BVHLAB_EXE [REPORT.html]  (a report given: only
# that one is checked, no sweep run)
set -euo pipefail
exe=$1
width=1400

if ! browser=$("$(dirname "$0")/../../scripts/chromium.sh" 2>/dev/null); then
	echo "report-layout: skipped: no chromium installed (apt-get install chromium)"
	exit 77
fi

tmp=$(mktemp -d /tmp/bvhlab-layout-XXXXXX)
trap 'rm -rf "$tmp"' EXIT

if [ $# -ge 2 ]; then
	report=$2
else
	# Long builder labels, build phases (lbvh's), three traversals and two
	# thread counts: the widest tables a small sweep makes.
	cat >"$tmp/layout.json" <<'EOF'
{ "output": "out", "repeat": 1, "threads": [1, 2],
  "rays": { "width": 16, "height": 16, "min_ms": 1, "rounds": 1,
            "traversal": ["wide", "stack", "stackless"] },
  "scenes": [ { "name": "ico", "generator": "icosphere", "frequency": 6 } ],
  "builders": [ { "plugin": "sah_seq", "name": "sah_seq_with_a_rather_long_label" },
                { "plugin": "sah_tasks" }, { "plugin": "lbvh" } ] }
EOF
	"$exe" run --quiet "$tmp/layout.json"
	report=$tmp/out/report.html
fi

# The report with a script that writes what it measured into the page.
page=$tmp/page.html
sed 's#</body></html>##' "$report" >"$page"
cat >>"$page" <<'EOF'
<script>
const w = window.innerWidth, bad = [];
let cells = 0;
if (document.documentElement.scrollWidth > w)
	bad.push('the page scrolls sideways: ' + document.documentElement.scrollWidth + ' px');
document.querySelectorAll('table').forEach((t, i) => t.querySelectorAll('th, td').forEach(c => {
	const r = c.getBoundingClientRect();
	cells++;
	if (r.right > w + 0.5 || r.left < 0 || r.width < 4)
		bad.push('table ' + i + ' cell "' + c.textContent.slice(0, 30) + '" at ' +
		         Math.round(r.left) + '..' + Math.round(r.right));
}));
document.body.insertAdjacentHTML('beforeend', '<pre id="lay' + 'out">' + /* not found in this text */
	(bad.length ? 'LAYOUT BAD at ' + w + ' px\n' + bad.slice(0, 20).join('\n')
	            : 'LAYOUT OK at ' + w + ' px, ' + cells + ' cells') + '</' + 'pre>');
</script>
</body></html>
EOF

"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
	--user-data-dir="$tmp/profile" --window-size=$width,1000 \
	--dump-dom "file://$page" >"$tmp/dom.html" 2>/dev/null
result=$(sed -n '/<pre id="layout">/,/<\/pre>/p' "$tmp/dom.html" | sed 's/<[^>]*>//g')
echo "report-layout: ${result:-no result (the script in the page did not run)}"
case $result in
"LAYOUT OK at $width px"*) exit 0 ;;
*) exit 1 ;;
esac
