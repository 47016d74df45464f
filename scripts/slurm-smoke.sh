#!/usr/bin/env bash
# Smoke test of `bvhlab plan --format slurm` on a real, single-node Slurm:
# starts munged, slurmctld and slurmd on this machine (Debian's slurm-wlm and
# munge, configured in a temporary folder, as root), submits the generated
# sweep.sbatch for a small plan, waits for the job array, merges the parts
# and checks the result against the plan. Every wait is bounded; every
# daemon it started is stopped on exit.
# Usage: scripts/slurm-smoke.sh [BUILD_DIR]   (default: build)
# Last line: "slurm-smoke: passed", "slurm-smoke: skipped: REASON" (exit 77)
# or "slurm-smoke: FAILED: REASON" (exit 1).
set -uo pipefail
case "${1:-}" in
-h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
esac
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" 2>/dev/null && pwd) || build=""
bvhlab="$build/app/bvhlab"
tmp="" pids=()

skip() { echo "slurm-smoke: skipped: $*"; exit 77; }
fail() {
	echo "slurm-smoke: FAILED: $*"
	for log in "$tmp"/*.log "$tmp"/sweep/slurm/*.out; do
		[ -f "$log" ] && { echo "--- $log"; tail -n 20 "$log"; }
	done
	exit 1
}

cleanup() {
	local pid
	for pid in "${pids[@]}"; do
		kill "$pid" 2>/dev/null
	done
	for pid in "${pids[@]}"; do
		# Bounded: a daemon that ignores SIGTERM gets SIGKILL after 10 s.
		timeout 10 tail --pid="$pid" -f /dev/null 2>/dev/null || kill -9 "$pid" 2>/dev/null
	done
	[ -n "$tmp" ] && rm -rf "$tmp"
}
trap cleanup EXIT

[ -x "$bvhlab" ] || skip "no bvhlab command at $bvhlab (build first)"
[ "$(id -u)" = 0 ] || skip "needs root to start slurmd and munged"
for cmd in munged mungekey slurmctld slurmd sbatch scontrol sinfo; do
	command -v "$cmd" >/dev/null 2>&1 ||
		skip "$cmd not found (Debian packages slurm-wlm and munge; scripts/setup.sh tries to install them)"
done

tmp=$(mktemp -d /tmp/bvhlab-slurm-XXXXXX) || skip "cannot make a temporary folder"
chmod 755 "$tmp"
host=$(hostname -s)
port=$((20000 + RANDOM % 20000))

# Waits up to $1 seconds for the command after it to succeed.
wait_for() {
	local limit=$1
	shift
	timeout "$limit" bash -c "until $*; do sleep 0.5; done" >/dev/null 2>&1
}

start_munge() {
	mkdir -p "$tmp/munge" && chmod 700 "$tmp/munge"
	mungekey --create --keyfile="$tmp/munge/munge.key" >/dev/null 2>&1 ||
		skip "mungekey could not create a key"
	chmod 400 "$tmp/munge/munge.key"
	munged --force --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/munge.socket" \
		--pid-file="$tmp/munge/munged.pid" --log-file="$tmp/munged.log" \
		--seed-file="$tmp/munge/munge.seed" --foreground >/dev/null 2>&1 &
	pids+=($!)
	wait_for 20 "test -S '$tmp/munge/munge.socket'" || skip "munged did not start (see its log)"
}

write_conf() {
	mkdir -p "$tmp/state" "$tmp/spool"
	cat >"$tmp/slurm.conf" <<EOF
ClusterName=bvhlab-smoke
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/builtin
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=smoke Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
	export SLURM_CONF="$tmp/slurm.conf"
}

start_slurm() {
	slurmctld -D -i -f "$SLURM_CONF" >/dev/null 2>&1 &
	pids+=($!)
	wait_for 30 "scontrol ping | grep -q UP" || skip "slurmctld did not start (see its log)"
	slurmd -D -f "$SLURM_CONF" -N "$host" >/dev/null 2>&1 &
	pids+=($!)
	wait_for 60 "sinfo -h -o %T | grep -qx idle" || skip "slurmd did not register as idle"
}

start_munge
write_conf
start_slurm

# A small plan: 2 scenes x sah_seq with a grid of 2 bin counts x threads
# 1, 2. sah_seq has no PARALLEL flag: once per scene, so 4 runs, and plan +
# merge must hold the same runs and not_applicable as one `bvhlab run`.
mkdir -p "$tmp/sweep"
cat >"$tmp/smoke.json" <<'EOF'
{ "repeat": 1, "threads": [1, 2], "validate_rays": 32, "rays": { "width": 8, "height": 8 },
  "scenes": [ { "generator": "icosphere", "frequency": 6 }, { "generator": "soup", "count": 300 } ],
  "builders": [ { "plugin": "sah_seq", "options": { "method": "binned", "bins": { "grid": [4, 8] } } } ] }
EOF
"$bvhlab" plan "$tmp/smoke.json" --out "$tmp/sweep" --format slurm --jobs 2 ||
	fail "bvhlab plan --format slurm"
grep -q -- '--array=0-3%2' "$tmp/sweep/sweep.sbatch" || fail "sweep.sbatch has no --array=0-3%2"
# --wait returns when the whole array has ended; bounded by timeout.
timeout 300 sbatch --wait --quiet "$tmp/sweep/sweep.sbatch" >"$tmp/sbatch.log" 2>&1 ||
	fail "the job array did not complete (sbatch --wait: $(tail -n 3 "$tmp/sbatch.log"))"
"$bvhlab" merge "$tmp"/sweep/parts/* --out "$tmp/sweep" 2>"$tmp/merge.log" ||
	fail "bvhlab merge: $(cat "$tmp/merge.log")"
grep -q "merged 4 of the plan's 4 runs" "$tmp/merge.log" || fail "merge: $(cat "$tmp/merge.log")"
"$bvhlab" run "$tmp/smoke.json" --out "$tmp/single" --quiet || fail "bvhlab run of the same config"
python3 - "$tmp/sweep/results.json" "$tmp/single/results.json" <<'EOF' || fail "merged runs differ from one run"
import json, sys
def key(path):
    doc = json.load(open(path))
    return [(r["id"], r["scene"], r["builder"], r["threads"], r["status"], r["tree"]["sah_cost"],
             r["tree"]["nodes"], r["validation"]["valid"]) for r in doc["runs"]], \
        doc.get("not_applicable")
(a, na), (b, nb) = key(sys.argv[1]), key(sys.argv[2])
sys.exit(0 if a == b and na == nb and len(a) == 4 and len(na) == 2 and
         all(k[4] == "ok" for k in a) else 1)
EOF
echo "slurm-smoke: passed"
