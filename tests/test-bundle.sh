#!/usr/bin/env bash
# The relocatable bundle (scripts/bundle.sh): made from this build, under
# 64 MiB, run in a clean environment (env -i, LD_LIBRARY_PATH only into the
# bundle) on a small config of generated scenes, it gives the build's trees
# (node count and SAH cost of every run), finds its plugins from its own
# file, says in one line that images are skipped (no images module), and
# loads every library it shares with the build from the bundle: the
# loader's own log (LD_DEBUG=libs) names each object it initialised, and
# any of them that the bundle carries (cJSON, hwloc, the OpenCL ICD loader,
# libstdc++, Embree, TBB, ...) must be the bundle's copy. Objects outside
# the bundle may only be the C library's and the OpenCL driver's (PoCL).
# Usage: tests/test-bundle.sh SOURCE_ROOT BUILD_ROOT
set -uo pipefail
src=$1 build=$2
fail() { echo "FAIL: $*"; exit 1; }

sanitize=$(python3 -c 'import json,sys
print(next(o["value"] for o in json.load(open(sys.argv[1])) if o["name"] == "b_sanitize"))' \
	"$build/meson-info/intro-buildoptions.json")
if [ "$sanitize" != none ]; then
	echo "SKIP: a bundle is made from a release build (this one has -Db_sanitize=$sanitize)"
	exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$src/scripts/bundle.sh" "$tmp/bundle" "$build" > "$tmp/bundle.log" 2>&1 ||
	fail "bundle.sh: $(cat "$tmp/bundle.log")"
bytes=$(du -sb "$tmp/bundle" | cut -f1)
[ "$bytes" -le $((64 * 1024 * 1024)) ] || fail "the bundle is $bytes bytes, over 64 MiB"
libdir=$(cd "$tmp/bundle" && dirname "$(dirname "$(ls -d lib*/bvhlab/plugins lib*/*/bvhlab/plugins 2>/dev/null | head -1)")")
[ -n "$libdir" ] && [ "$libdir" != . ] || fail "no plugin folder in the bundle"

cat > "$tmp/small.json" <<'EOF'
{
  "format_version": 1,
  "output": "out",
  "repeat": 1,
  "warmup": 0,
  "threads": [1, 2],
  "validate": true,
  "validate_rays": 64,
  "rays": { "width": 16, "height": 16, "diffuse": 0 },
  "images": true,
  "scenes": [
    { "name": "soup", "generator": "soup", "count": 3000, "seed": 1 },
    { "name": "terrain", "generator": "terrain", "size": 24, "seed": 1 }
  ],
  "builders": [
    { "plugin": "lbvh" },
    { "plugin": "sah_tasks" },
    { "plugin": "embree", "optional": true },
    { "plugin": "tinybvh", "optional": true },
    { "plugin": "cl_lbvh", "optional": true, "options": { "device": "cpu" } }
  ]
}
EOF
"$build/app/bvhlab" run "$tmp/small.json" --out "$tmp/build-out" --quiet \
	> "$tmp/build.log" 2>&1 || fail "the build's run: $(tail -5 "$tmp/build.log")"

# PATH and HOME only for the OpenCL driver: PoCL runs the system's linker
# and keeps its compiled kernels under HOME (the build's run made them).
mkdir "$tmp/ld"
env -i PATH=/usr/bin:/bin HOME="${HOME:-$tmp}" LD_LIBRARY_PATH="$tmp/bundle/$libdir/bvhlab/lib" \
	LD_DEBUG=libs LD_DEBUG_OUTPUT="$tmp/ld/log" \
	"$tmp/bundle/bin/bvhlab" run "$tmp/small.json" --out "$tmp/bundle-out" --quiet \
	> "$tmp/run.log" 2>&1 || fail "the bundle's run: $(tail -5 "$tmp/run.log")"
grep -q '^bvhlab: images skipped (.*bvhlab-images.so.*); the run goes on$' "$tmp/run.log" ||
	fail "no 'images skipped' line: $(head -3 "$tmp/run.log")"

python3 - "$tmp" "$libdir" <<'EOF' || exit 1
import glob, json, os, re, sys
tmp, libdir = sys.argv[1], sys.argv[2]
bundle = os.path.realpath(os.path.join(tmp, "bundle"))

def trees(folder):
    with open(os.path.join(tmp, folder, "results.json")) as f:
        runs = json.load(f)["runs"]
    return {(r["scene"], r["builder"], r["threads"]):
            (r["status"], r.get("tree", {}).get("nodes"), r.get("tree", {}).get("sah_cost"))
            for r in runs}

built, bundled = trees("build-out"), trees("bundle-out")
if built != bundled:
    sys.exit("FAIL: the trees differ:\n  build  %s\n  bundle %s" % (built, bundled))
bad = [k for k, v in built.items() if v[0] != "ok"]
if bad or len(built) < 8:
    sys.exit("FAIL: %d runs, not ok: %s" % (len(built), bad))

carried = set(os.listdir(os.path.join(bundle, libdir, "bvhlab", "lib")))
carried |= set(os.listdir(os.path.join(bundle, libdir, "bvhlab", "plugins")))
loaded = set()
for log in glob.glob(os.path.join(tmp, "ld", "log*")):
    with open(log, errors="replace") as f:
        loaded |= {m.group(1) for m in re.finditer(r"calling init: (\S+)", f.read())}
inside = {p for p in loaded if os.path.realpath(p).startswith(bundle + "/")}
leaked = sorted(p for p in loaded - inside if os.path.basename(p) in carried)
if leaked:
    sys.exit("FAIL: the bundle's libraries loaded from elsewhere: %s" % leaked)
names = {os.path.basename(p) for p in inside}
for need in ("libcjson.so.1", "libhwloc.so.15", "libOpenCL.so.1", "lbvh.so", "sah_tasks.so"):
    if need not in names and (need in carried or not need.startswith("libOpenCL")):
        sys.exit("FAIL: %s was not seen loaded from the bundle (%s)" % (need, sorted(names)))
others = sorted(os.path.basename(p) for p in loaded - inside)
print("bundle: %d runs with the build's trees; %d objects loaded from the bundle, "
      "%d from the system: %s" % (len(built), len(inside), len(others), " ".join(others)))
EOF
echo "bundle: $(cat "$tmp/bundle.log")"
