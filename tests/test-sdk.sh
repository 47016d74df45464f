#!/bin/sh
# The SDK end to end: installs bvhlab into a temporary prefix, builds the
# template plugin from a copy of examples/plugin-template against the
# installed files only (pkg-config), loads it with the installed bvhlab by
# path and then by name after installing it, and checks its tree is valid.
# Usage: test-sdk.sh SOURCE_ROOT
set -eu
src=$1
tmp=$(mktemp -d "${TMPDIR:-/tmp}/bvhlab-sdk.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
unset BVHLAB_PLUGIN_PATH PKG_CONFIG_PATH CFLAGS LDFLAGS

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

step "build the template out of tree"
cp -R "$src/examples/plugin-template" "$tmp/template"
meson setup "$tmp/tbuild" "$tmp/template" -Dwerror=true >"$tmp/tsetup.log" 2>&1 ||
	{ cat "$tmp/tsetup.log"; exit 1; }
ninja -C "$tmp/tbuild" >"$tmp/tbuild.log" 2>&1 || { cat "$tmp/tbuild.log"; exit 1; }
# Headers from the prefix, nothing from the source tree.
if grep -q -- "-I$src" "$tmp/tbuild/build.ninja"; then
	echo "the template saw the source tree's headers"; exit 1
fi

check() {
	out=$("$bvhlab" build "$1" icosphere:frequency=8) || { echo "$out"; exit 1; }
	echo "$out"
	echo "$out" | grep -q "^valid:      yes" || { echo "tree not valid"; exit 1; }
}

step "load it by path"
check "$tmp/tbuild/template.so"
step "install it into plugindir and load it by name"
ninja -C "$tmp/tbuild" install >/dev/null
check template
echo "sdk: ok"
