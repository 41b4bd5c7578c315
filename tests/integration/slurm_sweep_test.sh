#!/usr/bin/env bash
# deploy/sweep.sh --slurm on a real Slurm cluster of two nodes: a private munged, slurmctld and two slurmd (n1, n2),
# each slurmd in a network namespace host of its own (h1, h2 on a bridge, 10.79.0.0/24; the controller and the sweep
# on the bridge at .254; one CPU per node, so the two tasks land on both). A small matrix (ramp, teams 1 and 3, one
# seed, 60 steps) runs as one array job, each task in a private network namespace on its node; its CSV must equal the local sweep's (wall seconds aside) and every run
# must end on the local run's terrain_sha256. Bad input: --partition without --slurm, --slurm without sbatch, an
# unknown partition: exit 2, one line, nothing written.
# Usage: slurm_sweep_test.sh      Exits 77 (skipped) without slurm-wlm and munge (deploy/install-deps.sh --slurm) or
# without namespaces, bridges and veth pairs.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
sweep="$root/deploy/sweep.sh"
scenario="$root/deploy/scenarios/ramp.pbtxt"
fail() { echo "FAIL (slurm sweep): $*" >&2; exit 1; }
for tool in sbatch squeue sinfo scancel slurmctld slurmd munged nsenter; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool not installed (deploy/install-deps.sh --slurm)"; exit 77; }
done
[ "$(id -u)" -eq 0 ] || { echo "SKIP: the test cluster's daemons need root"; exit 77; }
if [ "${MARSALA_SLURM_INNER:-}" != 1 ]; then
  unshare -n -m --propagation private true 2>/dev/null || { echo "SKIP: no network and mount namespaces here"; exit 77; }
  exec env MARSALA_SLURM_INNER=1 unshare -n -m --propagation private bash "$0" "$@"
fi
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-it-slurm.XXXXXX")"
c="$work/cluster"
stop_cluster() {
  local f
  for f in "$c"/d-n1.pid "$c"/d-n2.pid "$c"/ctld.pid "$c"/munged.pid; do
    [ -f "$f" ] && kill "$(cat "$f")" 2>/dev/null || true
  done
  sleep 0.5
  [ -n "${MARSALA_KEEP_WORK:-}" ] || rm -rf "$work"
}
trap stop_cluster EXIT
. "$root/tests/integration/lib.sh"  # bridge_hosts, expect_tool_usage_error

# --- 1. bad input that needs no cluster ---------------------------------------------------------------------------
expect_tool_usage_error "$sweep" "$work" "--partition needs --slurm" --scenario "$scenario" --partition main
mkdir -p "$work/nobin"
for tool in bash dirname cat grep basename; do ln -s "$(command -v "$tool")" "$work/nobin/$tool"; done
ln -s "$(python3 -c 'import sys; print(sys.executable)')" "$work/nobin/python3"  # the interpreter, not a shim
PATH="$work/nobin" expect_tool_usage_error "$sweep" "$work" "--slurm: sbatch not found" --scenario "$scenario" --slurm
echo "ok: --partition without --slurm, --slurm without sbatch: exit 2, nothing written"

# --- 2. the cluster: munged, slurmctld, slurmd n1 on h1 and n2 on h2 ---------------------------------------------
bridge_hosts 10.79.0 2
ip addr add 10.79.0.254/24 dev br0
mkdir -p "$c/state" "$c/spooln1" "$c/spooln2"
munged --socket="$c/munge.sock" --pid-file="$c/munged.pid" --log-file="$c/munged.log" --seed-file="$c/munge.seed" \
  --force || fail "munged did not start"
cat >"$c/slurm.conf" <<CONF
ClusterName=marsalatest
SlurmctldHost=$(hostname -s)(10.79.0.254)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$c/munge.sock
StateSaveLocation=$c/state
SlurmdSpoolDir=$c/spool%n
SlurmctldPidFile=$c/ctld.pid
SlurmdPidFile=$c/d-%n.pid
SlurmctldLogFile=$c/ctld.log
SlurmdLogFile=$c/d-%n.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldPort=16917
SlurmdPort=16918
NodeName=n1 NodeAddr=10.79.0.1 CPUs=1 State=UNKNOWN
NodeName=n2 NodeAddr=10.79.0.2 CPUs=1 State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$c/slurm.conf"
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start ($(tail -n 3 "$c/ctld.log"))"
# nsenter, not ip netns exec: that one mounts a fresh /sys, without the cgroup file system slurmd looks for.
nsenter --net=/run/netns/h1 slurmd -f "$SLURM_CONF" -N n1 || fail "slurmd n1 did not start"
nsenter --net=/run/netns/h2 slurmd -f "$SLURM_CONF" -N n2 || fail "slurmd n2 did not start"
for _ in $(seq 1 100); do sinfo -h -o '%T %D' 2>/dev/null | grep -q '^idle 2$' && break; sleep 0.1; done
sinfo -h -o '%T %D' | grep -q '^idle 2$' || fail "the two nodes are not idle: $(sinfo 2>&1)"
echo "ok: slurmctld and two slurmd nodes up"

# --- 3. an unknown partition: exit 2, one line, nothing written, no job left ----------------------------------------
expect_tool_usage_error "$sweep" "$work" "Slurm partition 'nope' does not exist" --scenario "$scenario" --slurm \
  --partition nope
[ -z "$(squeue -h)" ] || fail "a job is queued after the refused partition"
echo "ok: an unknown partition: exit 2, nothing written or queued"

# --- 4. the same matrix, locally and on the cluster ---------------------------------------------------------------
matrix=(--scenario "$scenario" --teams "1 3" --seeds 1 --max-steps 60 --timeout 120 --no-plot)
"$sweep" "${matrix[@]}" --out "$work/local" >"$work/local.txt" 2>&1 || { cat "$work/local.txt"; fail "the local sweep"; }
"$sweep" "${matrix[@]}" --out "$work/slurm" --slurm --partition main >"$work/slurm.txt" 2>&1 ||
  { cat "$work/slurm.txt" "$work"/slurm/slurm/task-*.out; fail "the Slurm sweep failed"; }
grep -q "submitted Slurm array job" "$work/slurm.txt" || fail "no array job was submitted"
nodes=$(cat "$work"/slurm/slurm/task-*.out | grep -o ' on n[12]:' | sort -u | wc -l)
drop_wall() { cut -d, -f1-4,6- "$1"; }
[ "$(drop_wall "$work/local/sweep.csv")" = "$(drop_wall "$work/slurm/sweep.csv")" ] ||
  { diff <(drop_wall "$work/local/sweep.csv") <(drop_wall "$work/slurm/sweep.csv"); fail "the CSVs differ"; }
[ "$(wc -l <"$work/slurm/sweep.csv")" -eq 3 ] || fail "expected 2 rows"
for run in n1-s1 n3-s1; do
  here=$(jq -r .terrain_sha256 "$work/local/$run/summary.json")
  there=$(jq -r .terrain_sha256 "$work/slurm/$run/summary.json")
  [ -n "$here" ] && [ "$here" = "$there" ] || fail "$run: terrain_sha256 $there on Slurm, $here locally"
done
[ "$nodes" -eq 2 ] || fail "the tasks ran on $nodes node(s), not on both"
[ -z "$(squeue -h)" ] || fail "tasks are left in the queue"
echo "ok: 2 runs as one array job on $nodes node(s): the CSV and every terrain_sha256 equal the local sweep's"

# --- 5. a failed task: one task cancelled while it runs; the other's row is kept, the failed run is named, exit 1 ---
"$sweep" "${matrix[@]}" --max-steps 150 --out "$work/cut" --slurm >"$work/cut.txt" 2>&1 &
cut_pid=$!
job=""
for _ in $(seq 1 300); do
  job=$(squeue -h -t R -o '%i' 2>/dev/null | grep '_1$' || true)
  [ -n "$job" ] && break
  sleep 0.05
done
[ -n "$job" ] || { kill "$cut_pid"; fail "task 1 of the array job never ran"; }
scancel "$job"
rc=0
wait "$cut_pid" || rc=$?
[ "$rc" -eq 1 ] || { cat "$work/cut.txt"; fail "a sweep with a cancelled task exited $rc, expected 1"; }
grep -q "team 3, seed 1: FAILED" "$work/cut.txt" && grep -q "1 run(s) failed" "$work/cut.txt" ||
  { cat "$work/cut.txt"; fail "the failed run is not named"; }
[ "$(cut -d, -f1,2 "$work/cut/sweep.csv" | tail -n +2)" = "1,1" ] || { cat "$work/cut/sweep.csv"; fail "rows kept"; }
[ -z "$(squeue -h)" ] || fail "tasks are left in the queue after the failure"
echo "ok: a cancelled task: exit 1, the failed run named, the other run's row kept"
