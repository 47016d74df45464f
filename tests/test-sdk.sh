#!/bin/sh
# The SDK end to end, both ways a plugin author builds against bvhlab:
#  - against the checkout: PKG_CONFIG_PATH=BUILD/meson-uninstalled, headers
#    from the source tree, plugindir the build tree's plugins/;
#  - against an install: `meson install --destdir` into a temporary folder,
#    so bvhlab.pc must be relocatable (${pcfiledir}) and the installed
#    bvhlab must find its plugins from where it lies, not from its prefix.
# Each way builds copies of examples/plugin-template (C) and
# examples/plugin-template-cpp (C++17), checks each exports only its entry
# point and loads both through `bvhlab run` (every run ok, every tree
# valid); the installed C template is also installed and loaded by name.
# When bvhlab was built with OpenCL, the checkout's way also builds
# examples/plugin-template-cl with docs/gpu.md's commands and runs its
# compare.json (where there is a device), and the installed way builds
# it and, when the machine has an OpenCL device, builds a tree with it
# that must be valid and report its phases; with no device, the build
# must fail saying why.
# Usage: test-sdk.sh SOURCE_ROOT BUILD_ROOT
set -eu
src=$1
build=$2
tmp=$(mktemp -d "${TMPDIR:-/tmp}/bvhlab-sdk.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
unset BVHLAB_PLUGIN_PATH PKG_CONFIG_PATH CFLAGS CXXFLAGS LDFLAGS DESTDIR

step() { echo "== $*"; }
fail() { echo "FAIL: $*"; exit 1; }

# Copies examples/$2 and builds it out of tree as $1-$2; $3 is the module's name.
build_template() {
	step "$1: build $2 out of tree ($(pkg-config --cflags bvhlab))"
	cp -R "$src/examples/$2" "$tmp/$1-$2"
	meson setup "$tmp/$1-$2-build" "$tmp/$1-$2" -Dwerror=true >"$tmp/setup.log" 2>&1 ||
		{ cat "$tmp/setup.log"; fail "meson setup of $2 ($1)"; }
	ninja -C "$tmp/$1-$2-build" >"$tmp/build.log" 2>&1 ||
		{ cat "$tmp/build.log"; fail "build of $2 ($1)"; }
	exports=$(nm -D --defined-only "$tmp/$1-$2-build/$3.so" | awk '{print $3}')
	[ "$exports" = bvhlab_plugin_entry ] ||
		{ echo "$exports"; fail "$3.so exports more than its entry point"; }
}

# Runs both templates (by the plugin names or paths $2 and $3) with bvhlab $1.
run_both() {
	step "$1 run: template and template_cpp, 1 and 2 threads"
	cat >"$tmp/both.json" <<EOF
{ "format_version": 1, "output": "both-results", "repeat": 1, "warmup": 0,
  "threads": [1, 2], "validate_rays": 64,
  "rays": { "width": 32, "height": 32, "min_ms": 1, "rounds": 1 },
  "scenes": [ { "generator": "stadium", "count": 3000 } ],
  "builders": [ { "plugin": "$2" },
                { "plugin": "$3", "options": { "bins": 32, "max_leaf": 8 } } ] }
EOF
	rm -rf "$tmp/both-results"
	"$1" run "$tmp/both.json" --quiet || fail "bvhlab run failed"
	results=$tmp/both-results/results.json
	ok=$(grep -cE '"status":[[:space:]]*"ok"' "$results" || true)
	valid=$(grep -cE '"valid":[[:space:]]*true' "$results" || true)
	cpp=$(grep -cE '"builder":[[:space:]]*"template_cpp"' "$results" || true)
	echo "runs ok: $ok, valid trees: $valid, template_cpp runs: $cpp"
	# template is not PARALLEL: one run at 1 thread; template_cpp: 1 and 2.
	[ "$ok" = 3 ] && [ "$valid" = 3 ] && [ "$cpp" = 2 ] || { cat "$results"; fail "runs"; }
}

step "against the checkout: $build/meson-uninstalled"
export PKG_CONFIG_PATH="$build/meson-uninstalled"
[ "$(pkg-config --variable=plugindir bvhlab)" = "$build/plugins" ] ||
	fail "uninstalled plugindir is $(pkg-config --variable=plugindir bvhlab)"
build_template tree plugin-template template
build_template tree plugin-template-cpp template_cpp
grep -q -- "-I$src/include" "$tmp/tree-plugin-template-build/build.ninja" ||
	fail "the uninstalled build did not use the source tree's include/"
run_both "$build/app/bvhlab" "$tmp/tree-plugin-template-build/template.so" \
	"$tmp/tree-plugin-template-cpp-build/template_cpp.so"

# The OpenCL template as docs/gpu.md says, from a copy of the checkout's
# root: a setup without PKG_CONFIG_PATH stops naming the one to give; with
# it, the template builds and its compare.json runs (every run ok).
cl_template_checkout() {
	step "against the checkout: the OpenCL template, docs/gpu.md's commands"
	mkdir "$tmp/root" && cp -R "$src/examples/plugin-template-cl" "$tmp/root/mygpu"
	out=$(cd "$tmp/root" && env -u PKG_CONFIG_PATH meson setup mygpu/build mygpu 2>&1) &&
		fail "the OpenCL template configured without bvhlab.pc?"
	echo "$out" | grep -q 'PKG_CONFIG_PATH=$PWD/build/meson-uninstalled' ||
		{ echo "$out"; fail "no PKG_CONFIG_PATH hint when bvhlab is not found"; }
	rm -rf "$tmp/root/mygpu/build"
	(cd "$tmp/root" && PKG_CONFIG_PATH=$build/meson-uninstalled \
		meson setup mygpu/build mygpu -Dwerror=true >"$tmp/setup.log" 2>&1 &&
		ninja -C mygpu/build >"$tmp/build.log" 2>&1) ||
		{ cat "$tmp/setup.log" "$tmp/build.log"; fail "the OpenCL template against the checkout"; }
	if ! "$build/app/bvhlab" info --machine --json | grep -q '"compute_units"'; then
		echo "== its compare.json skipped: no OpenCL device on this machine"
		return
	fi
	"$build/app/bvhlab" run "$tmp/root/mygpu/compare.json" --repeat 1 --quiet ||
		{ cat "$tmp/root/mygpu/results/results.json"; fail "compare.json of the OpenCL template"; }
	csv=$tmp/root/mygpu/results/results.csv
	mine=$(grep -c '^[a-z]*,mine,template_cl,ok,1,' "$csv" || true)
	echo "compare.json: every run ok, $(($(wc -l <"$csv") - 1)) runs, $mine of the template"
	[ "$mine" = 2 ] || { cat "$csv"; fail "compare.json: $mine ok runs of the template, not 2"; }
}
if [ -f "$build/plugins/cl_lbvh/cl_lbvh.so" ] && pkg-config --exists OpenCL; then
	cl_template_checkout
else
	echo "== OpenCL template against the checkout skipped: bvhlab was built without OpenCL"
fi

step "install with --destdir into $tmp/stage"
meson install -C "$build" --no-rebuild --destdir "$tmp/stage" >"$tmp/install.log" 2>&1 ||
	{ cat "$tmp/install.log"; fail "meson install"; }
pc=$(find "$tmp/stage" -name bvhlab.pc)
[ -n "$pc" ] || fail "no bvhlab.pc installed"
export PKG_CONFIG_PATH=$(dirname "$pc")
bvhlab=$(find "$tmp/stage" -path '*/bin/bvhlab' -type f)
[ -x "$bvhlab" ] || fail "no bin/bvhlab installed"
plugindir=$(pkg-config --variable=plugindir bvhlab)
echo "pkg-config: $(pkg-config --cflags bvhlab) | plugindir $plugindir"
[ -f "$plugindir/sah_seq.so" ] || fail "sah_seq.so not in plugindir $plugindir"
"$bvhlab" list --names | grep -qx sah_seq || fail "installed bvhlab does not list sah_seq"

build_template inst plugin-template template
build_template inst plugin-template-cpp template_cpp
if grep -q -- "-I$src" "$tmp/inst-plugin-template-build/build.ninja"; then
	fail "the installed build saw the source tree's headers"
fi
step "install the C template into plugindir: loaded by name"
ninja -C "$tmp/inst-plugin-template-build" install >/dev/null
[ -f "$plugindir/template.so" ] || fail "template.so not installed into $plugindir"
run_both "$bvhlab" template "$tmp/inst-plugin-template-cpp-build/template_cpp.so"

# The OpenCL template, against the install, when bvhlab has OpenCL.
if [ -n "$(find "$tmp/stage" -path '*/bvhlab/opencl.h')" ] && pkg-config --exists OpenCL; then
	build_template inst plugin-template-cl template_cl
	step "the OpenCL template on the machine's device"
	so=$tmp/inst-plugin-template-cl-build/template_cl.so
	if "$bvhlab" info --machine --json | grep -q '"compute_units"'; then
		out=$("$bvhlab" build "$so" icosphere:frequency=8 -o device=auto) ||
			{ echo "$out"; fail "the OpenCL template's build"; }
		echo "$out"
		echo "$out" | grep -q "^valid:      yes" || fail "OpenCL template: tree not valid"
		echo "$out" | grep -q "^phase:      device" || fail "OpenCL template: no device phase"
	else
		out=$("$bvhlab" build "$so" icosphere:frequency=8 2>&1) &&
			fail "the OpenCL template built without a device?"
		echo "$out" | grep -q "OpenCL" || { echo "$out"; fail "no OpenCL message"; }
		echo "no OpenCL device here: the template says so: $out"
	fi
else
	echo "== OpenCL template skipped: bvhlab was built without OpenCL"
fi
echo "sdk: ok"
