#!/usr/bin/env bash
# The conventions every program keeps (inside run_isolated.sh):
#   version: --version on every program prints "<program> <version> (git <revision>)", the revision of the tree it was
#            built from, and exits 0.
#   json-log: a real ramp run (world, 3 agents) with --log-format json or MARSALA_LOG_FORMAT=json, and a monitor
#            with --log-format json: every stderr line of each is one JSON object with time, level, process, pid,
#            msg, and an agent's carry its id; events.log is JSON Lines, a deposition with its cells.
# Usage: conventions_test.sh CASE DOMAIN
set -euo pipefail
case_name="$1"
domain="$2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=lib.sh
. "$here/lib.sh"
test_workspace conventions

case "$case_name" in
  version)
    revision=$(git -C "$root" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
    for program in marsala-world marsala-agent marsala-monitor marsala-terrain; do
      text=$("$bin/$program" --version) || fail "$program --version exited non-zero"
      echo "$text" | grep -Eq "^$program [0-9]+\.[0-9]+\.[0-9]+ \(git ($revision(-dirty)?|unknown)\)$" ||
        fail "$program --version printed '$text' (expected '$program X.Y.Z (git $revision)')"
      echo "ok: $text"
    done
    ;;
  json-log)
    # The processes started here, not by spawn.sh, to keep each one's stderr apart from its stdout (its answer).
    scenario="$root/deploy/scenarios/ramp.pbtxt"
    mkdir -p "$work/logs"
    "$bin/marsala-world" --scenario "$scenario" --agents 3 --dds cyclone --domain "$domain" --out "$work/run" \
      --log-format json >"$work/world.out" 2>"$work/logs/world.log" &
    world=$!
    pids=()
    for id in 1 2 3; do  # agents 2 and 3 take the format from the environment
      if [ "$id" -eq 1 ]; then format=(--log-format json); else format=(); fi
      MARSALA_LOG_FORMAT=json "$bin/marsala-agent" --scenario "$scenario" --id "$id" --dds cyclone --domain "$domain" \
        "${format[@]}" >/dev/null 2>"$work/logs/agent-$id.log" &
      pids+=($!)
    done
    wait "$world" || { tail -5 "$work/logs/world.log"; fail "the world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero (see $work/logs)"; done
    grep -q "completed after 298 steps, 3 agents, terrain sha256 d008eb1c" "$work/world.out" ||
      fail "not the reference ramp run: $(cat "$work/world.out")"
    # A monitor that finds no world (the run is over): its error, in json, is a record too.
    if "$bin/marsala-monitor" --log-format json status --dds cyclone --domain "$domain" --timeout 0.5 \
      >/dev/null 2>"$work/monitor.log"; then fail "marsala-monitor status found a world on an empty domain"; fi
    python3 - "$work/logs" "$work/monitor.log" "$work/run/events.log" <<'EOF' || fail "see above"
import json, os, sys
logs, monitor, events = sys.argv[1], sys.argv[2], sys.argv[3]
files = [os.path.join(logs, f) for f in sorted(os.listdir(logs))] + [monitor]
seen = {}
for path in files:
    lines = open(path, encoding="utf-8").read().splitlines()
    if not lines:
        sys.exit(f"{path}: no log line")
    for n, line in enumerate(lines, 1):
        try:
            record = json.loads(line)
        except ValueError as e:
            sys.exit(f"{path}:{n}: not a JSON object ({e}): {line!r}")
        if not isinstance(record, dict) or set(record) != {"time", "level", "process", "agent_id", "pid", "msg"}:
            sys.exit(f"{path}:{n}: not a log record: {line!r}")
        name = os.path.basename(path)
        want = "world" if name == "world.log" else "monitor" if path == monitor else "agent"
        if record["process"] != want:
            sys.exit(f"{path}:{n}: process {record['process']!r}, expected {want!r}")
        if want == "agent" and record["agent_id"] != int(name[len("agent-"):-len(".log")]):
            sys.exit(f"{path}:{n}: agent_id {record['agent_id']!r} in {name}")
        if want != "agent" and record["agent_id"] is not None:
            sys.exit(f"{path}:{n}: agent_id {record['agent_id']!r} for the {want}")
        seen[name] = seen.get(name, 0) + 1
if not any(json.loads(l)["level"] == "error" for l in open(monitor)):
    sys.exit("the monitor's error is no record at level error")
kinds, cells = {}, 0
for n, line in enumerate(open(events, encoding="utf-8"), 1):
    e = json.loads(line)
    kinds[e["kind"]] = kinds.get(e["kind"], 0) + 1
    if e["kind"] == "deposited":
        if not e["cells"] or any(len(c) != 3 for c in e["cells"]):
            sys.exit(f"events.log:{n}: a deposition without its cells: {line!r}")
        cells += len(e["cells"])
if kinds.get("deposited", 0) == 0 or kinds.get("run_over") != 1:
    sys.exit(f"events.log: kinds {kinds}")
print("ok: log lines (all JSON):", ", ".join(f"{k} {v}" for k, v in seen.items()),
      f"| events.log: {sum(kinds.values())} objects, {kinds['deposited']} depositions of {cells} cells")
EOF
    ;;
  *) echo "unknown case '$case_name'" >&2; exit 2 ;;
esac
