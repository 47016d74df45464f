#!/bin/sh
# The SDK end to end: installs bvhlab into a temporary prefix, builds the
# template plugins from copies of examples/plugin-template (C) and
# examples/plugin-template-cpp (C++17) against the installed files only
# (pkg-config), checks each exports only its entry point, loads the C one
# with the installed bvhlab by path and then by name after installing it,
# and runs the C++ one through `bvhlab run` beside sah_seq: every run ok,
# every tree valid. When bvhlab was built with OpenCL (bvhlab/opencl.h
# installed), it builds examples/plugin-template-cl too and, when the
# machine has an OpenCL device, builds a tree with it that must be valid
# and report its phases; with no device, the build must fail saying why.
# Usage: test-sdk.sh SOURCE_ROOT
set -eu
src=$1
tmp=$(mktemp -d "${TMPDIR:-/tmp}/bvhlab-sdk.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
unset BVHLAB_PLUGIN_PATH PKG_CONFIG_PATH CFLAGS CXXFLAGS LDFLAGS

step() { echo "== $*"; }

step "install bvhlab into $tmp/prefix"
meson setup "$tmp/build" "$src" --prefix="$tmp/prefix" -Dbuildtype=release \
	-Dtests=false -Dembree=disabled >"$tmp/setup.log" 2>&1 || { cat "$tmp/setup.log"; exit 1; }
ninja -C "$tmp/build" install >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; exit 1; }

pc=$(find "$tmp/prefix" -name bvhlab.pc)
[ -n "$pc" ] || { echo "no bvhlab.pc installed"; exit 1; }
export PKG_CONFIG_PATH=$(dirname "$pc")
plugindir=$(pkg-config --variable=plugindir bvhlab)
echo "pkg-config: $(pkg-config --cflags bvhlab) | plugindir $plugindir"
[ -f "$plugindir/sah_seq.so" ] || { echo "sah_seq.so not in plugindir"; exit 1; }
bvhlab=$tmp/prefix/bin/bvhlab

# Copies examples/$1 and builds it out of tree; $2 is the module's name.
build_template() {
	step "build $1 out of tree"
	cp -R "$src/examples/$1" "$tmp/$1"
	meson setup "$tmp/$1-build" "$tmp/$1" -Dwerror=true >"$tmp/$1-setup.log" 2>&1 ||
		{ cat "$tmp/$1-setup.log"; exit 1; }
	ninja -C "$tmp/$1-build" >"$tmp/$1-build.log" 2>&1 || { cat "$tmp/$1-build.log"; exit 1; }
	# Headers from the prefix, nothing from the source tree.
	if grep -q -- "-I$src" "$tmp/$1-build/build.ninja"; then
		echo "$1 saw the source tree's headers"; exit 1
	fi
	exports=$(nm -D --defined-only "$tmp/$1-build/$2.so" | awk '{print $3}')
	[ "$exports" = bvhlab_plugin_entry ] ||
		{ echo "$2.so exports more than its entry point:"; echo "$exports"; exit 1; }
}

check() {
	out=$("$bvhlab" build "$1" icosphere:frequency=8) || { echo "$out"; exit 1; }
	echo "$out"
	echo "$out" | grep -q "^valid:      yes" || { echo "tree not valid"; exit 1; }
}

build_template plugin-template template
step "load it by path"
check "$tmp/plugin-template-build/template.so"
step "install it into plugindir and load it by name"
ninja -C "$tmp/plugin-template-build" install >/dev/null
check template

build_template plugin-template-cpp template_cpp
step "bvhlab run: the C++ template and sah_seq, 2 scenes, 1 and 2 threads"
cat >"$tmp/cpp.json" <<EOF
{ "format_version": 1, "output": "cpp-results", "repeat": 1, "warmup": 0,
  "threads": [1, 2],
  "scenes": [ { "generator": "icosphere", "frequency": 16 },
              { "generator": "stadium", "count": 3000 } ],
  "builders": [ { "plugin": "$tmp/plugin-template-cpp-build/template_cpp.so",
                  "options": { "bins": 32, "max_leaf": 8 } },
                { "plugin": "sah_seq", "options": { "method": "binned" } } ] }
EOF
"$bvhlab" run "$tmp/cpp.json" --quiet || { echo "bvhlab run failed"; exit 1; }
results=$tmp/cpp-results/results.json
runs=$(grep -cE '"status":[[:space:]]*"ok"' "$results" || true)
valid=$(grep -cE '"valid":[[:space:]]*true' "$results" || true)
cpp=$(grep -cE '"builder":[[:space:]]*"template_cpp"' "$results" || true)
echo "runs ok: $runs of 8, valid trees: $valid, template_cpp runs: $cpp"
[ "$runs" = 8 ] && [ "$valid" = 8 ] && [ "$cpp" = 4 ] || { cat "$results"; exit 1; }

if [ -f "$tmp/prefix/include/bvhlab/opencl.h" ] && pkg-config --exists OpenCL; then
	build_template plugin-template-cl template_cl
	step "the OpenCL template on the machine's device"
	if "$bvhlab" info --machine --json | grep -q '"compute_units"'; then
		out=$("$bvhlab" build "$tmp/plugin-template-cl-build/template_cl.so" \
			icosphere:frequency=8 -o device=auto) || { echo "$out"; exit 1; }
		echo "$out"
		echo "$out" | grep -q "^valid:      yes" || { echo "tree not valid"; exit 1; }
		echo "$out" | grep -q "^phase:      device" || { echo "no device phase"; exit 1; }
	else
		out=$("$bvhlab" build "$tmp/plugin-template-cl-build/template_cl.so" \
			icosphere:frequency=8 2>&1) && { echo "built without a device?"; exit 1; }
		echo "$out" | grep -q "OpenCL" || { echo "$out"; exit 1; }
		echo "no OpenCL device here: the template says so: $out"
	fi
else
	echo "== OpenCL template skipped: bvhlab was built without OpenCL"
fi
echo "sdk: ok"
