#!/usr/bin/env bash
# Sets everything up (Debian packages, meson build) and runs the whole test
# suite: the release build, then ASan+UBSan, then ThreadSanitizer (threaded
# code), each in its own build directory. Ends with "N passed, N failed".
# Usage: scripts/test.sh [--quick]   (--quick: the release build only)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=setup.sh
. "$here/setup.sh"

quick=0
case "${1:-}" in
--quick) quick=1 ;;
-h|--help) sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
esac

passed=0 failed=0 skipped=0
suite_s=0 # wall seconds in meson test, all suites (goal: well under 15 min)

# Counts one failure of the suite itself (not of a test), with the reason.
suite_broken() {
	echo "test.sh: $1" >&2
	failed=$((failed + 1))
}

# Runs `meson test` in a build dir and adds its counts to the totals. The
# log is removed first, so a run that never starts cannot count the last
# one's results; a suite that selects no test, runs fewer tests than it
# defines, or fails without a failed test counts as a failure.
run_suite() {
	local label=$1 dir=$2
	shift 2
	echo "== $label ==" >&2
	local log="$dir/meson-logs/testlog.json"
	local defined rc ran ok fail skip
	defined=$(meson test -C "$dir" --list "$@" 2>/dev/null | grep -c ' / ' || true)
	rm -f "$log"
	local start=$SECONDS
	meson test -C "$dir" --print-errorlogs "$@"
	rc=$?
	suite_s=$((suite_s + SECONDS - start))
	echo "== $label: $((SECONDS - start)) s of wall time ==" >&2
	if [ ! -f "$log" ]; then
		suite_broken "$label: meson test did not run (exit status $rc)"
		return
	fi
	ran=$(grep -c '"result": ' "$log" || true)
	ok=$(grep -c '"result": "OK"' "$log" || true)
	fail=$(grep -cE '"result": "(FAIL|TIMEOUT|ERROR|UNEXPECTEDPASS)"' "$log" || true)
	skip=$(grep -c '"result": "SKIP"' "$log" || true)
	passed=$((passed + ok)); failed=$((failed + fail)); skipped=$((skipped + skip))
	[ "$defined" -gt 0 ] || suite_broken "$label: the suite selects no test"
	[ "$ran" -ge "$defined" ] || suite_broken "$label: $ran of the $defined tests ran"
	[ "$rc" = 0 ] || [ "$fail" -gt 0 ] ||
		suite_broken "$label: meson test exited with status $rc and no failed test"
}

# Builds one build dir; an existing one is reconfigured with the options
# first, so a folder set up without the sanitizers gets them.
build_or_count() {
	local label=$1 dir=$2
	shift 2
	if [ -f "$dir/build.ninja" ] && [ $# -gt 0 ] && ! meson configure "$dir" "$@" >&2; then
		suite_broken "$label: cannot reconfigure $dir with $*"
		return 1
	fi
	if ! setup_build "$dir" "$@"; then
		suite_broken "$label build failed"
		return 1
	fi
}

# The Slurm smoke test (scripts/slurm-smoke.sh): counted as one test, skipped
# with its reason where Slurm cannot be started (not root, no slurm-wlm).
run_slurm_smoke() {
	echo "== slurm smoke ==" >&2
	local out rc
	out=$(bash "$here/slurm-smoke.sh" "$BVHLAB_ROOT/build" 2>&1)
	rc=$?
	echo "$out" | tail -n 30 >&2
	case $rc in
	0) passed=$((passed + 1)) ;;
	77) skipped=$((skipped + 1)) ;;
	*) failed=$((failed + 1)) ;;
	esac
}

build_or_count release "$BVHLAB_ROOT/build" && run_suite release "$BVHLAB_ROOT/build"

if [ $quick = 0 ]; then
	[ -x "$BVHLAB_ROOT/build/app/bvhlab" ] && run_slurm_smoke
	san_opts=(-Dbuildtype=debugoptimized -Db_lundef=false)
	# intercept_tls_get_addr=0: gcc 12's interceptor can misread a thread's
	# dynamic TLS block and LeakSanitizer then crashes at exit ("Tracer caught
	# signal 11", google/sanitizers#1322; tests/meson.build). Leaks are still
	# checked: cli-plan-parallel's in-process run crashed 3 of 3 without it and
	# passed 3 of 3 with it.
	export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0
	export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
	build_or_count asan "$BVHLAB_ROOT/build-asan" "${san_opts[@]}" -Db_sanitize=address,undefined &&
		run_suite "asan+ubsan" "$BVHLAB_ROOT/build-asan" --timeout-multiplier 4
	export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1
	build_or_count tsan "$BVHLAB_ROOT/build-tsan" "${san_opts[@]}" -Db_sanitize=thread &&
		run_suite tsan "$BVHLAB_ROOT/build-tsan" --suite plugins --suite core \
			--no-suite sequential --timeout-multiplier 6
fi

echo "test.sh: $((suite_s / 60)) min $((suite_s % 60)) s of wall time in the test suites" >&2
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" = 0 ]
