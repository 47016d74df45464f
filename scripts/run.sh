#!/usr/bin/env bash
# Sets everything up (Debian packages, meson build) and runs an experiment.
# Usage: scripts/run.sh [CONFIG.json] [bvhlab run options...]
# Default config: configs/default.json (generated scenes only, every plugin built, < 1 minute of CPU).
# Running again starts afresh: unless --resume or --force is given, --force
# is passed, so the earlier results are moved aside (results.json.1, ...).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=setup.sh
. "$here/setup.sh"

case "${1:-}" in
-h|--help)
	sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'
	exit 0
	;;
esac

config=${1:-$BVHLAB_ROOT/configs/default.json}
[ $# -gt 0 ] && shift
[ -f "$config" ] || { echo "run.sh: no such config: $config" >&2; exit 2; }

fresh=--force
for a in "$@"; do
	case "$a" in --resume|--force) fresh= ;; esac
done

setup_build "$BVHLAB_ROOT/build"
exec "$BVHLAB_ROOT/build/app/bvhlab" run "$config" ${fresh:+"$fresh"} "$@"
