#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang, ASan+UBSan, -Dfuzz=true) in
# build-fuzz/ and runs each for SECONDS (default 600), one after another.
# Inputs found to crash land in build-fuzz/crashes/; copy each into
# tests/fuzz-regress/ (test-bad-input loads every one).
# Usage: scripts/fuzz.sh [SECONDS] [obj|ply|config ...]
# (extra libFuzzer flags in $BVHLAB_FUZZ_FLAGS, e.g. -use_value_profile=1)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=setup.sh
. "$here/setup.sh"

case "${1:-}" in
-h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
esac
seconds=${1:-600}
shift || true
targets=("$@")
[ ${#targets[@]} = 0 ] && targets=(obj ply config)
build=${BVHLAB_FUZZ_BUILD:-$BVHLAB_ROOT/build-fuzz}

# clang and its libFuzzer runtime (libclang-rt-N-dev on Debian 12).
fuzz_missing_debs() {
	local missing="" probe
	if ! command -v clang >/dev/null 2>&1; then
		echo "clang"
		return
	fi
	probe=$(mktemp -d)
	printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n)\n{ (void)d; (void)n; return 0; }\n' \
		>"$probe/t.c"
	if ! clang -fsanitize=fuzzer "$probe/t.c" -o "$probe/t" >/dev/null 2>&1; then
		missing="libclang-rt-$(clang -dumpversion | cut -d. -f1)-dev"
	fi
	rm -rf "$probe"
	echo "$missing"
}

install_fuzz_deps() {
	install_deps || return 1
	local missing
	missing=$(fuzz_missing_debs)
	[ -z "$missing" ] && return 0
	apt_install fuzz "$missing" || return 1
	# clang alone may still lack the runtime
	missing=$(fuzz_missing_debs)
	[ -z "$missing" ] && return 0
	apt_install fuzz "$missing"
}

install_fuzz_deps || exit 1
if [ ! -f "$build/build.ninja" ]; then
	# clang++ too: the core has C++ (the OpenImageIO writer), so C++ links
	# the targets, and only clang's driver knows -fsanitize=fuzzer.
	CC=clang CXX=clang++ meson setup "$build" "$BVHLAB_ROOT" -Dfuzz=true -Dtests=false \
		-Dbuildtype=debugoptimized -Db_lundef=false -Db_sanitize=address,undefined >&2 || exit 1
fi
ninja -C "$build" "${targets[@]/#/fuzz/fuzz-}" >&2 || exit 1

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
status=0
mkdir -p "$build/crashes"
python3 "$BVHLAB_ROOT/fuzz/seeds.py" "$build/seeds" || exit 1
for t in "${targets[@]}"; do
	corpus="$build/corpus/$t"
	mkdir -p "$corpus"
	echo "== fuzz-$t: $seconds s ==" >&2
	# The seeds are regenerated each time; what libFuzzer adds goes to the build's corpus.
	"$build/fuzz/fuzz-$t" "$corpus" "$build/seeds/$t" \
		-dict="$BVHLAB_ROOT/fuzz/$t.dict" -max_total_time="$seconds" -max_len=4096 \
		-timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
		-artifact_prefix="$build/crashes/$t-" ${BVHLAB_FUZZ_FLAGS:-} || status=1
done
if ls "$build/crashes/"* >/dev/null 2>&1; then
	echo "fuzz: inputs that failed are in $build/crashes/" >&2
	status=1
fi
exit $status
