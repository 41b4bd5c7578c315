#!/usr/bin/env bash
# The live view (marsala-monitor serve) in a real browser against a real run: headless Chromium loads the page while
# a world and three agents (deploy/spawn.sh, tests/integration/scenarios/ramp_live.pbtxt) run on DDS, and the test
# checks what the page shows: the robot count and table rows equal the agents started, the step shown advances
# between two looks while the run goes on, the terrain picture is there, several browsers at once see the same, the
# end of the run shows as completed at the summary's step; then a replay of the run folder; and the usage errors
# (unknown option, bad port, port in use: exit 2 naming what). Runs inside run_isolated.sh's network namespace,
# where the page's port is private to the test. Exit 77 (skipped) when chromium is not installed
# (MARSALA_CHROMIUM names another browser binary).
# Usage: live_view_test.sh DOMAIN
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
bin="${MARSALA_BUILD_DIR:?MARSALA_BUILD_DIR must name the build folder}/bin"
domain="${1:?usage: live_view_test.sh DOMAIN}"
# shellcheck source=lib.sh
. "$here/lib.sh"

chromium="${MARSALA_CHROMIUM:-chromium}"  # the browser to drive (a name on PATH or a path)
if ! command -v "$chromium" >/dev/null 2>&1; then
  echo "SKIP: $chromium is not installed (deploy/install-deps.sh --browser installs Debian's chromium)"
  exit 77
fi

port=18765 replay_port=18766 busy_port=18767
work="$(mktemp -d /tmp/marsala-live-view.XXXXXX)"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [ "${keep:-0}" -eq 1 ]; then echo "outputs kept in $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  keep=1
  for f in "$work"/*.log "$work"/run/logs/*.log; do [ -f "$f" ] && { echo "--- $f" >&2; tail -n 20 "$f" >&2; }; done
  exit 1
}

# browse URL OUT: the DOM after the page's scripts ran for a while (polls, the terrain picture).
browse() {
  "$chromium" --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir="$work/chrome-$RANDOM$RANDOM" \
    --virtual-time-budget=2500 --window-size=1400,800 --dump-dom "$1" >"$2" 2>>"$work/chromium.log"
}
# shot URL PNG: a screenshot of the page.
shot() {
  "$chromium" --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir="$work/chrome-$RANDOM$RANDOM" \
    --virtual-time-budget=2500 --window-size=1400,800 --screenshot="$2" "$1" >>"$work/chromium.log" 2>&1
}
# what DOM: a value the page shows (step, robot-count, rows, phase, terrain-version, roles).
what() {
  python3 - "$1" "$2" <<'PY'
import re, sys
kind, dom = sys.argv[1], open(sys.argv[2]).read()
def element_text(i):
    m = re.search(r'id="%s"[^>]*>([^<]*)<' % i, dom)
    return m.group(1) if m else ''
if kind == 'rows': print(len(re.findall(r'<tr class="agent-row', dom)))
elif kind == 'roles': print(' '.join(re.findall(r'data-role="([a-z]+)"', dom)))
elif kind == 'terrain-version':
    m = re.search(r'id="terrain-info"[^>]*data-version="(\d+)"', dom) or re.search(r'data-version="(\d+)"[^>]*id="terrain-info"', dom)
    print(m.group(1) if m else 0)
else: print(element_text(kind))
PY
}
# api_state PORT FIELD: a field of the run in the state document, or empty before a world status.
api_state() {
  python3 - "$1" "$2" <<'PY'
import json, sys, urllib.request
try:
    s = json.load(urllib.request.urlopen('http://127.0.0.1:%s/api/state' % sys.argv[1], timeout=5))
except Exception:
    print(''); sys.exit(0)
run = s.get('run') or {}
print({'map': 'yes' if s.get('map') else ''}.get(sys.argv[2], run.get(sys.argv[2], '')))
PY
}
# wait_for PORT FIELD VALUE SECONDS: until the state's field has that value.
wait_for() {
  for _ in $(seq 1 $((4 * $4))); do
    [ "$(api_state "$1" "$2")" = "$3" ] && return 0
    sleep 0.25
  done
  return 1
}

monitor="$bin/marsala-monitor"

# Usage errors: exit 2 and a message naming what is wrong.
rc=0; "$monitor" serve --bogus >"$work/usage.out" 2>&1 || rc=$?
[ "$rc" -eq 2 ] && grep -q -- "--bogus" "$work/usage.out" || fail "unknown option: exit $rc, $(cat "$work/usage.out")"
rc=0; "$monitor" serve --port 70000 >"$work/usage.out" 2>&1 || rc=$?
[ "$rc" -eq 2 ] && grep -q -- "--port" "$work/usage.out" || fail "bad port: exit $rc, $(cat "$work/usage.out")"
# The port is taken before the monitor starts (a loaded machine may take seconds to start python: a fixed sleep let
# the monitor take the port itself and serve until the test's timeout); the monitor gets 30 s to say so.
python3 -c 'import socket,sys,time; s=socket.socket(); s.bind(("127.0.0.1", int(sys.argv[1]))); s.listen(1); open(sys.argv[2], "w").close(); time.sleep(120)' \
  "$busy_port" "$work/busy.ready" & pids+=("$!")
for _ in $(seq 1 240); do [ -f "$work/busy.ready" ] && break; sleep 0.25; done
[ -f "$work/busy.ready" ] || fail "could not take port $busy_port for the port-in-use case"
rc=0; timeout 30 "$monitor" serve --port "$busy_port" --domain "$domain" >"$work/usage.out" 2>&1 || rc=$?
[ "$rc" -eq 2 ] && grep -q "port $busy_port" "$work/usage.out" && grep -q "in use" "$work/usage.out" ||
  fail "port in use: exit $rc, $(cat "$work/usage.out")"
echo "ok: usage errors exit 2 naming what ($(tail -1 "$work/usage.out"))"

# The live run: the monitor first (it waits for the world and the run folder), then world + 3 agents.
run="$work/run"
mkdir -p "$run"
"$monitor" serve --port "$port" --dds cyclone --domain "$domain" --run-dir "$run" >"$work/serve.log" 2>&1 &
serve_pid=$!; pids+=("$serve_pid")
"$root/deploy/spawn.sh" --scenario "$here/scenarios/ramp_live.pbtxt" --agents 3 --dds cyclone --domain "$domain" \
  --out "$run" --quiet >"$work/spawn.log" 2>&1 &
spawn_pid=$!; pids+=("$spawn_pid")

wait_for "$port" phase running 120 || fail "the state never showed the run running"
wait_for "$port" map yes 60 || fail "the state never got the terrain"
url="http://127.0.0.1:$port/"
browse "$url" "$work/dom1.html"
phase1="$(what phase "$work/dom1.html")"
step1="$(what step "$work/dom1.html")"
sleep 1
browse "$url" "$work/dom2.html"
step2="$(what step "$work/dom2.html")"
echo "page: phase '$phase1' step $step1, then step $step2; robots $(what robot-count "$work/dom2.html"), rows $(what rows "$work/dom2.html"), roles: $(what roles "$work/dom2.html")"
[ "$phase1" = "running" ] || fail "first look: phase '$phase1', not running"
[[ "$step1" =~ ^[0-9]+$ && "$step2" =~ ^[0-9]+$ ]] || fail "no step on the page ('$step1', '$step2')"
[ "$step2" -gt "$step1" ] || fail "the step did not advance between two looks ($step1, then $step2)"
for dom in "$work/dom1.html" "$work/dom2.html"; do
  [ "$(what robot-count "$dom")" = 3 ] || fail "robot count '$(what robot-count "$dom")' on the page, 3 agents started"
  [ "$(what rows "$dom")" = 3 ] || fail "$(what rows "$dom") rows in the agents' table, 3 agents started"
  [ "$(what terrain-version "$dom")" -ge 1 ] || fail "no terrain picture on the page"
done
for role in $(what roles "$work/dom2.html"); do
  case "$role" in active|following|returning|done) ;; *) fail "a live robot shown as '$role'" ;; esac
done
echo "ok: the page shows 3 robots, the terrain, and the step advancing ($step1 -> $step2)"

# Several browsers at once see the same run.
many=()
for k in 1 2 3; do browse "$url" "$work/many$k.html" & many+=("$!"); done
for pid in "${many[@]}"; do wait "$pid" || true; done
for k in 1 2 3; do
  [ "$(what robot-count "$work/many$k.html")" = 3 ] || fail "browser $k of 3 at once: robots '$(what robot-count "$work/many$k.html")'"
  [ "$(what step "$work/many$k.html")" -ge "$step2" ] || fail "browser $k of 3 at once: step went back"
done
echo "ok: three browsers at once each show 3 robots"

shot "$url" "$work/live.png"
is_png "$work/live.png" && [ "$(stat -c %s "$work/live.png")" -gt 20000 ] || fail "no screenshot of the page"

rc=0; wait "$spawn_pid" || rc=$?
[ "$rc" -eq 0 ] || fail "the run did not complete (spawn.sh exit $rc)"
steps="$(field steps "$run/summary.json")"
wait_for "$port" phase completed 30 || fail "the state never showed the run completed"
browse "$url" "$work/dom-end.html"
[ "$(what phase "$work/dom-end.html")" = completed ] || fail "after the run: phase '$(what phase "$work/dom-end.html")'"
[ "$(what step "$work/dom-end.html")" = "$steps" ] ||
  fail "after the run the page shows step $(what step "$work/dom-end.html"), summary.json $steps"
echo "ok: the page shows the run completed at step $steps, as summary.json says"
kill -TERM "$serve_pid"
rc=0; wait "$serve_pid" || rc=$?
[ "$rc" -eq 0 ] || fail "serve ended with $rc on SIGTERM"

# A replay of the run folder, without DDS, at 500 steps/s: the same robots, the step advancing, then the end.
"$monitor" serve --port "$replay_port" --replay "$run" --speed 500 >"$work/replay.log" 2>&1 &
replay_pid=$!; pids+=("$replay_pid")
wait_for "$replay_port" phase running 30 || fail "the replay never showed running"
rurl="http://127.0.0.1:$replay_port/"
browse "$rurl" "$work/replay1.html"
browse "$rurl" "$work/replay2.html"
r1="$(what step "$work/replay1.html")" r2="$(what step "$work/replay2.html")"
[ "$(what robot-count "$work/replay2.html")" = 3 ] || fail "replay: robots '$(what robot-count "$work/replay2.html")'"
[ "$r2" -gt "$r1" ] || [ "$r2" = "$steps" ] || fail "replay: the step did not advance ($r1, then $r2)"
wait_for "$replay_port" phase completed 60 || fail "the replay never reached the run's end"
[ "$(api_state "$replay_port" step)" = "$steps" ] || fail "replay ended at step $(api_state "$replay_port" step), not $steps"
echo "ok: the replay shows 3 robots, the step advancing ($r1 -> $r2) and the end at step $steps"
