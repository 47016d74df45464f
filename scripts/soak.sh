#!/usr/bin/env bash
# Soak test of `bvhlab run`: N random configs (generated and adversarial
# scenes, real builders, plugins that crash, hang, leak or return broken
# trees), each sweep killed at a random moment and resumed, half of them
# after the config changed (a scene or its file, a builder's options or
# animation, the measurement or rays); checks that results.json always
# parses, no finished run is lost or duplicated, every kept run was made
# under the config it is resumed under, every run the change concerns is
# made again (and no other), and the exit status matches the runs. Builds
# the release tree first if needed.
# Usage: scripts/soak.sh N [BUILD_DIR] [SEED]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
case "${1:-}" in
''|-h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
esac
n=$1
build=${2:-$here/../build}
if [ ! -x "$build/app/bvhlab" ]; then
	# shellcheck source=setup.sh
	. "$here/setup.sh"
	setup_build "$build"
fi
exec python3 "$here/soak.py" "$n" "$build" ${3:+"$3"}
