#!/usr/bin/env bash
# bvhlab on a GPU node, in one command: `bvhlab info --machine`, then
# bench/gpu.json with its device builders (cl_lbvh, cl_ploc) on the first
# GPU (device "gpu") beside their CPU twins (lbvh, ploc, sah_tasks) in the
# same sweep, for the ratios. Into OUTDIR: machine.txt, results.json,
# report.md, the whole results folder (results/), and summary.txt, the one
# line it also prints last.
# Usage: gpu-check.sh [--cpu] [--limit SECONDS] OUTDIR
#   --cpu        the device builders on device "cpu" instead (PoCL): runs
#                the same sweep where there is no GPU, to the end unless
#                --limit is given (the check that it all runs; a few
#                minutes)
#   --limit S    stop the sweep after S seconds (default on a GPU 450, so
#                that the whole stays under 8 minutes); what finished is kept
# Runs from a bundle (scripts/bundle.sh DIR puts it at DIR/gpu-check.sh)
# or from a checkout with a build in build/. Needs python3. Exit status: 0
# every run done; 3 no OpenCL GPU (one line saying so; nothing run); 4 the
# limit stopped the sweep; 1 anything else. docs/gpu.md says how to use it.
set -uo pipefail
device=gpu limit=
while [ $# -gt 0 ]; do
	case "$1" in
	--cpu) device=cpu ;;
	--limit) limit=${2:-}; shift ;;
	-h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
	-*) echo "gpu-check: unknown option $1 (--help)" >&2; exit 1 ;;
	*) break ;;
	esac
	shift
done
[ $# -eq 1 ] || { echo "usage: gpu-check.sh [--cpu] [--limit SECONDS] OUTDIR" >&2; exit 1; }
[ -n "$limit" ] || [ "$device" = cpu ] || limit=450
[ -z "$limit" ] || [[ "$limit" =~ ^[0-9]+$ ]] ||
	{ echo "gpu-check: --limit wants seconds" >&2; exit 1; }
out=$1
here=$(cd "$(dirname "$0")" && pwd)
if [ -x "$here/bin/bvhlab" ]; then # a bundle
	bvhlab="$here/bin/bvhlab" config="$here/bench/gpu.json"
else # scripts/ of a checkout
	bvhlab="$here/../build/app/bvhlab" config="$here/../bench/gpu.json"
fi
[ -x "$bvhlab" ] || { echo "gpu-check: no bvhlab at $bvhlab" >&2; exit 1; }
command -v python3 >/dev/null || { echo "gpu-check: needs python3" >&2; exit 1; }
mkdir -p "$out" || exit 1
out=$(cd "$out" && pwd)

"$bvhlab" info --machine > "$out/machine.txt" 2>&1
"$bvhlab" info --machine --json > "$out/machine.json" 2>/dev/null
# The first device of the kind, "P:D NAME", or nothing.
first=$(python3 - "$out/machine.json" "$device" <<'EOF'
import json, sys
cl = json.load(open(sys.argv[1])).get("opencl", {})
for d in cl.get("devices", []):
    if d["kind"] == sys.argv[2]:
        print(d["device"], d["name"])
        break
EOF
)
if [ -z "$first" ]; then
	icd=$(sed -n 's/^OpenCL ICD: //p' "$out/machine.txt")
	echo "gpu-check: no OpenCL ${device^^} found (ICD: ${icd:-unknown}); nothing run" |
		tee "$out/summary.txt"
	exit 3
fi
cat "$out/machine.txt"

# bench/gpu.json with the device named and the scenes' paths absolute.
python3 - "$config" "$out/gpu-check.json" "$device" <<'EOF'
import json, os, sys
src, dst, device = sys.argv[1:]
cfg = json.load(open(src))
for s in cfg["scenes"]:
    if "path" in s:
        s["path"] = os.path.normpath(os.path.join(os.path.dirname(src), s["path"]))
for b in cfg["builders"]:
    if b["plugin"].startswith("cl_"):
        b.setdefault("options", {})["device"] = device
cfg["output"] = "results"
json.dump(cfg, open(dst, "w"), indent=2)
EOF
[ $? -eq 0 ] || exit 1
echo "gpu-check: bench/gpu.json on ${first#* } (device $device)${limit:+, at most $limit s}"
${limit:+timeout --signal=INT --kill-after=20 "$limit"} \
	"$bvhlab" run "$out/gpu-check.json" --out "$out/results" --force
rc=$?
cp "$out/results/results.json" "$out/results/report.md" "$out/" 2>/dev/null

# One line: per scene, each device builder's median, device time, device
# triangles per second and ratio to its CPU twin's best thread count.
python3 - "$out/results.json" "${first#* }" "$rc" <<'EOF' | tee "$out/summary.txt"
import json, sys
path, name, rc = sys.argv[1], sys.argv[2], int(sys.argv[3])
try:
    doc = json.load(open(path))
except (OSError, ValueError):
    print("gpu-check: %s: no results (bvhlab run exited %d)" % (name, rc)); sys.exit()
tris = {s["name"]: s.get("triangles", 0) for s in doc.get("scenes", [])}
runs = [r for r in doc.get("runs", []) if r.get("status") == "ok"]
def med(r): return r["build_ms"]["median"]
parts = []
for scene in tris:
    here = [r for r in runs if r["scene"] == scene]
    for dev, twin in (("cl_lbvh", "lbvh"), ("cl_ploc", "ploc")):
        d = [r for r in here if r["builder"] == dev]
        t = [r for r in here if r["builder"] == twin]
        if not d:
            parts.append("%s %s not ok" % (scene, dev)); continue
        dev_ms = d[0].get("build_phases", {}).get("device")
        best = min(t, key=med) if t else None
        parts.append("%s %s %.2f ms (device %s, %s Mtris/s)%s" % (
            scene, dev, med(d[0]),
            "%.2f ms" % dev_ms if dev_ms else "?",
            "%.3g" % (tris[scene] / dev_ms / 1e3) if dev_ms else "?",
            " = %.2fx %s@%d" % (med(d[0]) / med(best), twin, best["threads"]) if best else ""))
state = "done" if rc == 0 else "stopped by the limit" if rc in (124, 130, 137) else "exit %d" % rc
print("gpu-check: %s, %d runs ok, %s: %s" % (name, len(runs), state, "; ".join(parts)))
EOF
case $rc in
0|1) exit 0 ;; # 1: a run not ok, which the summary says
124|130|137) exit 4 ;;
*) exit 1 ;;
esac
