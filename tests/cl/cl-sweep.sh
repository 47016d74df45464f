#!/bin/sh
# Usage: cl-sweep.sh BVHLAB
# A sweep naming the device builders beside lbvh, run twice: with OpenCL's
# drivers hidden (OCL_ICD_VENDORS at an empty folder) the cl_* runs are
# `failed` with the message that says what to install and lbvh's run is
# ok; with the machine's drivers, every run is ok and the device runs
# carry build_phases (device no more than build_ms), the device they ran
# on (name, kind, compute units; in the CSV too) and the OpenCL runtime's
# memory apart from the build's, and report.md's fronts show them in a
# group of their own ("device: NAME"), never at a CPU thread count. Skips
# (77) when the machine has no OpenCL device. With the device's memory
# capped low (BVHLAB_CL_MEM_CAP_MB) the cl_* runs fail with the figures.
set -u
bvhlab=$1
dir=$(mktemp -d /tmp/bvhlab-cl-sweep-XXXXXX) || exit 1
trap 'rm -rf "$dir"' EXIT
cat > "$dir/sweep.json" <<JSON
{
  "format_version": 1, "repeat": 1, "warmup": 0, "threads": [1, 2], "validate": true,
  "scenes": [ { "name": "soup", "generator": "soup", "count": 500, "seed": 3 } ],
  "builders": [ { "plugin": "cl_lbvh" }, { "plugin": "cl_ploc" }, { "plugin": "lbvh" } ]
}
JSON
check() { # check RESULTS_DIR python-assertions...
	python3 - "$1/results.json" "$2" "${3:-}" <<'PY'
import json, sys
import csv, os
runs = json.load(open(sys.argv[1]))["runs"]
by = {r["builder"]: r for r in runs if r["threads"] == 1}
folder = os.path.dirname(sys.argv[1])
exec(sys.argv[2])
PY
}
OCL_ICD_VENDORS="$dir/none" "$bvhlab" run "$dir/sweep.json" --out "$dir/none" >"$dir/log" 2>&1
check "$dir/none" '
for b in ("cl_lbvh", "cl_ploc"):
    assert by[b]["status"] == "failed", by[b]
    assert "no OpenCL platform found" in by[b]["error"], by[b]["error"]
    assert "pocl-opencl-icd" in by[b]["error"], by[b]["error"]
    assert "device" not in by[b], by[b]
assert by["lbvh"]["status"] == "ok", by["lbvh"]
print("no drivers: cl_* failed with the message, lbvh ok")
' || { cat "$dir/log"; exit 1; }
# Device memory sized before any kernel: with the limits capped low, both
# device builders fail with the need and the limit, never a driver error.
for cap in 0.2 0.05; do
	BVHLAB_CL_MEM_CAP_MB=$cap "$bvhlab" run "$dir/sweep.json" --out "$dir/cap$cap" \
		>"$dir/log" 2>&1
	check "$dir/cap$cap" '
cap = sys.argv[3]
if "no OpenCL platform" in by["cl_lbvh"].get("error", "") or "no such OpenCL device" in by["cl_lbvh"].get("error", ""):
    print("skip: no OpenCL device:", by["cl_lbvh"]["error"]); sys.exit(77)
import re
want = (r"cl: (\d+\.\d\d) MiB of device memory needed, .* has 0\.20 MiB "
        if cap == "0.2" else
        r"a buffer of (\d+\.\d\d) MiB is more than .* allows in one allocation, 0\.05 MiB ")
for b in ("cl_lbvh", "cl_ploc"):
    assert by[b]["status"] == "failed", by[b]
    m = re.search(want + r"\(capped by \$BVHLAB_CL_MEM_CAP_MB\)", by[b]["error"])
    assert m and float(m.group(1)) > float(cap), by[b]["error"]
assert by["lbvh"]["status"] == "ok", by["lbvh"]
print("memory capped at", cap, "MiB:", by["cl_lbvh"]["error"])
' "$cap"
	rc=$?
	[ $rc = 0 ] || { [ $rc = 77 ] || cat "$dir/log"; exit $rc; }
done
"$bvhlab" run "$dir/sweep.json" --out "$dir/dev" >"$dir/log" 2>&1
check "$dir/dev" '
if "no OpenCL platform" in by["cl_lbvh"].get("error", "") or "no such OpenCL device" in by["cl_lbvh"].get("error", ""):
    print("skip: no OpenCL device:", by["cl_lbvh"]["error"]); sys.exit(77)
for b in ("cl_lbvh", "cl_ploc", "lbvh"):
    assert by[b]["status"] == "ok", by[b]
for b in ("cl_lbvh", "cl_ploc"):
    ph = by[b]["build_phases"]
    assert set(ph) == {"upload", "device", "download", "convert"}, ph
    assert 0 <= ph["device"] <= by[b]["build_ms"]["median"], (ph, by[b]["build_ms"])
    dev = by[b]["device"]
    assert dev["name"] and dev["kind"] in ("gpu", "cpu", "accelerator", "other"), dev
    assert dev["compute_units"] >= 1 and ":" in dev["index"], dev
    mem = by[b]["memory"]
    assert mem["runtime_bytes"] > 0 and mem["runtime_bytes"] <= mem["start_rss_bytes"], mem
assert "device" not in by["lbvh"] and "runtime_bytes" not in by["lbvh"]["memory"]
rows = {(r["builder"], r["threads"]): r for r in csv.DictReader(open(folder + "/results.csv"))}
assert rows[("cl_ploc", "1")]["device.name"] == by["cl_ploc"]["device"]["name"], rows
assert rows[("lbvh", "1")]["device.name"] == "", rows
report = open(folder + "/report.md").read()
fronts = report[report.index("### Pareto fronts"):]
fronts = fronts[:fronts.index("\n### ", 5)]
for b in ("cl_lbvh", "cl_ploc"):
    lines = [l for l in fronts.splitlines() if l.startswith("| %s |" % b)]
    assert lines == [l for l in lines if l.startswith("| %s | device: %s |" % (b, by[b]["device"]["name"]))], lines
    assert len(lines) == 1, lines
# The summary rows: a device builder says "device", never a thread
# count, and its Pareto verdict comes from the device group.
summary = report[report.index("## Summary"):]
summary = summary[:summary.index("\n## ")]
for b in ("cl_lbvh", "cl_ploc"):
    lines = [l for l in summary.splitlines() if l.startswith("| %s |" % b)]
    assert len(lines) == 1 and lines[0].startswith("| %s | device |" % b), lines
    assert "on 1 of 1 scene" in lines[0], lines
    runs_table = [l for l in report.splitlines() if l.startswith("| %s | " % b) and "| ok |" in l]
    assert runs_table and all(l.startswith("| %s | device | ok |" % b) for l in runs_table), runs_table
print("with drivers: every run ok, device phases within build_ms, on",
      by["cl_lbvh"]["device"]["name"], "(runtime %.1f MiB, the cl_lbvh build %.1f MiB)" %
      (by["cl_lbvh"]["memory"]["runtime_bytes"] / 2**20, by["cl_lbvh"]["memory"]["peak_bytes"] / 2**20))
'
rc=$?
[ $rc = 0 ] || [ $rc = 77 ] || cat "$dir/log"
exit $rc
