#!/usr/bin/env bash
# The world's Prometheus metrics (marsala-world --metrics-port, docs/runtime.md#metrics), inside run_isolated.sh:
# Debian's real prometheus server scrapes a ramp run of 3 agents every second; after the run its HTTP query API gives
# back the values the world served last, which must be summary.json's (steps, deposited volume, rejections, misses,
# admitted agents, surplus requests, progress), with the run state `completed` (the world lingers with its final
# values) and more than one scrape taken. A metrics port in use (Prometheus's own) exits 2 with one line naming it and
# writes nothing, from marsala-world and spawn.sh alike. 77 = skipped without prometheus (deploy/install-deps.sh).
# Usage: metrics_test.sh DOMAIN
set -euo pipefail
case_name=prometheus
domain="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=lib.sh
. "$here/lib.sh"
test_workspace metrics
command -v prometheus >/dev/null || { echo "SKIP: prometheus is not installed (deploy/install-deps.sh)"; exit 77; }

metrics_port=19464 prom_port=19090  # a private network namespace: nothing else listens here
cat >"$work/prometheus.yml" <<YML
global:
  scrape_interval: 1s
  scrape_timeout: 1s
scrape_configs:
  - job_name: marsala-world
    static_configs:
      - targets: ['127.0.0.1:$metrics_port']
YML
prometheus --config.file="$work/prometheus.yml" --storage.tsdb.path="$work/tsdb" \
  --web.listen-address="127.0.0.1:$prom_port" >"$work/prometheus.log" 2>&1 &
prom_pid=$!
trap 'kill "$prom_pid" 2>/dev/null; wait "$prom_pid" 2>/dev/null; rm -rf "$work"' EXIT
api="http://127.0.0.1:$prom_port"
# get PATH: the body of a GET on Prometheus's API, or nothing
get() { python3 -c 'import sys, urllib.request; print(urllib.request.urlopen(sys.argv[1], timeout=5).read().decode())' "$api$1" 2>/dev/null || true; }
for _ in $(seq 1 100); do
  [ "$(get /-/ready)" != "" ] && break
  sleep 0.2
done
[ "$(get /-/ready)" != "" ] || { tail -5 "$work/prometheus.log"; fail "prometheus did not get ready"; }

started=$(date +%s.%N)
"$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 3 --dds cyclone --domain "$domain" \
  --out "$work/run" --timeout 120 --quiet --metrics-port "$metrics_port" --trace "$work/trace.json" ||
  { tail -20 "$work/run/logs/world.log"; fail "spawn.sh --metrics-port $metrics_port"; }
took=$(python3 -c "import time; print(round(time.time() - $started, 1))")

# The values Prometheus holds, as their last sample (the series are marked stale once the world has gone, which
# last_over_time skips), compared with summary.json.
python3 - "$api" "$work/run/summary.json" <<'PY' || fail "Prometheus's values differ from summary.json"
import json, sys, urllib.parse, urllib.request
api, summary = sys.argv[1], json.load(open(sys.argv[2]))

def query(expr):
    url = f"{api}/api/v1/query?query={urllib.parse.quote(expr)}"
    answer = json.load(urllib.request.urlopen(url, timeout=5))
    result = answer["data"]["result"]
    if answer["status"] != "success" or len(result) != 1:
        sys.exit(f"{expr}: {answer}")
    return float(result[0]["value"][1])

def last(name):
    return f"last_over_time({name}[5m])"

checks = {
    last("marsala_steps_total"): float(summary["steps"]),
    last("marsala_deposited_volume_m3_total"): summary["deposited_volume_m3"],
    last("marsala_rejected_requests_total"): float(summary["rejected_requests"]),
    last("marsala_unattributed_rejections_total"): float(summary["unattributed_rejections"]),
    f'sum({last("marsala_rejections_total")})':
        float(summary["rejected_requests"] + summary["unattributed_rejections"]),
    last("marsala_deadline_misses_total"): float(summary["missed_deadlines"]),
    last("marsala_surplus_requests_total"): float(summary["surplus_requests"]),
    last("marsala_agents_admitted"): float(summary["admitted"]),
    last("marsala_agents_expected"): float(summary["agents"]),
    last("marsala_progress_ratio"): summary["progress"],
    last('marsala_run_state{state="completed"}'): 1.0 if summary["end_reason"] == "completed" else 0.0,
    f'sum({last("marsala_agent_requests_accepted_total")})': float(sum(a["accepted"] for a in summary["per_agent"])),
    last("marsala_step_duration_seconds_count"): float(summary["steps"]),
}
bad = []
for expr, want in checks.items():
    got = query(expr)
    ok = abs(got - want) <= 1e-12 * max(1.0, abs(want))
    print(f"{'ok' if ok else 'DIFFERS'}: {expr} = {got!r} (summary.json: {want!r})")
    if not ok:
        bad.append(expr)
cpu_s = query(last("process_cpu_seconds_total"))
print(f"ok: the world used {cpu_s:.2f} s of CPU by its last scrape")
if not cpu_s > 0:
    bad.append("no process_cpu_seconds_total")
scrapes = query("count_over_time(marsala_steps_total[5m])")
print(f"ok: {scrapes:.0f} scrapes of the run")
if scrapes < 2:
    bad.append(f"only {scrapes:.0f} scrapes")
if summary["steps"] < 100 or summary["end_reason"] != "completed":
    bad.append(f"the run did not complete as ramp 3 does: {summary['end_reason']} after {summary['steps']} steps")
sys.exit(f"differ: {bad}" if bad else 0)
PY
echo "ok: the run took ${took} s with Prometheus scraping it"

# The same run's step trace: each agent's track holds its own decision (reported in its requests) inside its answer,
# with its CPU time, on most steps (a step whose answer the world read in under the agent's own decision time still
# nests: the span is cut to the answer).
python3 - "$work/trace.json" "$work/run/summary.json" <<'PY' || fail "the agents' decisions are not in the trace"
import json, sys
events = [e for e in json.load(open(sys.argv[1]))["traceEvents"] if e["ph"] == "X"]
summary = json.load(open(sys.argv[2]))
answers = {(e["tid"], e["args"]["step"]): e for e in events if e["name"] == "answer"}
decides = [e for e in events if e["name"] == "decide"]
bad = []
for d in decides:
    a = answers.get((d["tid"], d["args"]["step"]))
    if a is None or d["ts"] < a["ts"] - 0.001 or d["ts"] + d["dur"] > a["ts"] + a["dur"] + 0.002:
        bad.append(f"decide of agent {d['tid']} at step {d['args']['step']} outside its answer")
    if "cpu_us" not in d["args"]:
        bad.append(f"decide of agent {d['tid']} at step {d['args']['step']} without cpu_us")
for agent in (1, 2, 3):
    mine = [d for d in decides if d["tid"] == agent]
    print(f"ok: agent {agent}: {len(mine)} decisions traced of {summary['steps']} steps")
    if len(mine) < 0.9 * summary["steps"]:
        bad.append(f"agent {agent}: {len(mine)} decisions traced over {summary['steps']} steps")
sys.exit(f"{bad[:5]}" if bad else 0)
PY

# A port in use (Prometheus's): one line naming it, exit 2, no folder; spawn.sh stops at its check, nothing started.
rc=0
"$bin/marsala-world" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 1 --domain "$domain" \
  --out "$work/refused" --metrics-port "$prom_port" >"$work/out.txt" 2>"$work/err.txt" || rc=$?
[ "$rc" -eq 2 ] || fail "marsala-world --metrics-port $prom_port (in use) exited $rc, not 2"
[ "$(wc -l <"$work/err.txt")" -eq 1 ] || fail "not one line: $(cat "$work/err.txt")"
grep -q -- "--metrics-port $prom_port: cannot listen on 127.0.0.1 port $prom_port: the port is in use" "$work/err.txt" ||
  fail "the message does not name the port: $(cat "$work/err.txt")"
[ ! -e "$work/refused" ] || fail "marsala-world wrote $work/refused for a port in use"
rc=0
"$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 1 --domain "$domain" \
  --out "$work/refused" --quiet --metrics-port "$prom_port" >/dev/null 2>"$work/err.txt" || rc=$?
[ "$rc" -eq 2 ] || fail "spawn.sh --metrics-port $prom_port (in use) exited $rc, not 2"
[ ! -e "$work/refused" ] || fail "spawn.sh made $work/refused for a port in use"
echo "ok: a metrics port in use: $(head -1 "$work/err.txt")"
