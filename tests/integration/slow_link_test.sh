#!/usr/bin/env bash
# A slow link does not collapse (issue 30 deliverable 4, docs/runtime.md#resends): ramp 3 on VENDOR, its first
# STEPS steps over loopback limited to 1 Mbit/s with MTU 1500 (tc tbf; netem is not in every kernel), end on the
# terrain of the same steps unthrottled, run first in the same test, with no missed deadline, no drop, and at most
# 3 times the unthrottled run's bytes on the wire. Before the resend rule every agent was dropped by step 4 there.
#
# VENDOR is cyclone (default, its loopback profile) or fastdds (deploy/dds/fastdds-slow.xml, the Fast DDS profile for
# slow links, docs/runtime.md#slow-links, in both runs).
#
# Usage: slow_link_test.sh STEPS DOMAIN [VENDOR], inside run_isolated.sh (tc changes this namespace's lo only);
# 77 = skipped where tbf cannot be set up.
set -euo pipefail
case_name="slow-link"
steps="$1"
domain="$2"
vendor="${3:-cyclone}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
. "$here/lib.sh"  # field, test_workspace
test_workspace slow_link
scenario="$root/deploy/scenarios/ramp.pbtxt"
case "$vendor" in
  cyclone) unset MARSALA_DDS_CONFIG ;;
  fastdds) export MARSALA_DDS_CONFIG="$root/deploy/dds/fastdds-slow.xml" ;;
  *) fail "VENDOR must be cyclone or fastdds, got '$vendor'" ;;
esac

# lo_bytes: bytes sent on this namespace's lo so far (/proc/net/dev is per namespace; /sys may show the host's).
lo_bytes() { awk '/^ *lo:/ { print $10 }' /proc/net/dev; }
# run NAME: ramp 3 for $steps steps into $work/NAME; prints the bytes it sent on lo.
run() {
  local before
  before=$(lo_bytes)
  MARSALA_BUILD_DIR="$(dirname "$bin")" "$root/deploy/spawn.sh" --scenario "$scenario" --agents 3 --domain "$domain" \
    --dds "$vendor" --max-steps "$steps" --out "$work/$1" --quiet --timeout 240 >/dev/null 2>"$work/$1.err" || true
  [ -f "$work/$1/summary.json" ] || { cat "$work/$1.err"; fail "$1: no summary.json"; }
  echo $(($(lo_bytes) - before))
}

# A bad rate limit in the profile (docs/runtime.md#slow-links): every program refuses it before anything runs, one line
# naming the property and the file, exit 2, the world's folder never made.
if [ "$vendor" = fastdds ]; then
  bad="$work/bad-rate.xml"
  sed 's#<name>marsala.rate.period_ms</name><value>40</value>#<name>marsala.rate.period_ms</name><value>soon</value>#' \
    "$MARSALA_DDS_CONFIG" >"$bad"
  grep -q '<value>soon</value>' "$bad" || fail "fastdds-slow.xml has no marsala.rate.period_ms of 40 to spoil"
  for program in "world --scenario $scenario --agents 3 --out $work/bad-out" "agent --scenario $scenario --id 1" \
                 "monitor status"; do
    set +e
    # shellcheck disable=SC2086  # the program's words
    MARSALA_DDS_CONFIG="$bad" "$bin"/marsala-$program --dds fastdds --domain "$domain" \
      >/dev/null 2>"$work/bad.err"
    code=$?
    set -e
    [ "$code" = 2 ] && [ "$(wc -l <"$work/bad.err")" = 1 ] && grep -q "marsala.rate.period_ms.*'soon'" "$work/bad.err" &&
      grep -q "$bad" "$work/bad.err" || { cat "$work/bad.err"; fail "marsala-${program%% *}: exit $code on a bad rate"; }
  done
  [ ! -e "$work/bad-out" ] || fail "the world made its folder before refusing a bad rate"
fi

ip link set lo mtu 1500 || { echo "SKIP: cannot set lo's MTU"; exit 77; }
clean_bytes=$(run clean)
sha=$(field terrain_sha256 "$work/clean/summary.json")
[ "$(field steps "$work/clean/summary.json")" = "$steps" ] || fail "the unthrottled run did not reach step $steps"

tc qdisc add dev lo root tbf rate 1mbit burst 32kbit latency 400ms 2>/dev/null || { echo "SKIP: no tbf qdisc here"; exit 77; }
start=$(date +%s)
slow_bytes=$(run slow)
seconds=$(($(date +%s) - start))
summary="$work/slow/summary.json"
[ "$(field steps "$summary")" = "$steps" ] && [ "$(field end_reason "$summary")" = "max_steps" ] ||
  { cat "$summary"; tail -5 "$work/slow/logs/world.log"; fail "at 1 Mbit/s the run ended before step $steps"; }
[ "$(field terrain_sha256 "$summary")" = "$sha" ] ||
  fail "at 1 Mbit/s the terrain after $steps steps is $(field terrain_sha256 "$summary"), unthrottled $sha"
[ "$(field missed_deadlines "$summary")" = 0 ] && ! grep -q '"kind":"dropped"' "$work/slow/events.log" ||
  { grep '"kind":"\(missed\|dropped\)"' "$work/slow/events.log" | head; fail "missed deadlines or drops at 1 Mbit/s"; }
[ "$slow_bytes" -le $((3 * clean_bytes)) ] ||
  fail "at 1 Mbit/s $slow_bytes bytes on the wire, more than 3 times the unthrottled $clean_bytes"
echo "ok: $vendor: $steps steps at 1 Mbit/s in $seconds s on the unthrottled terrain $sha; bytes on lo $slow_bytes" \
  "(unthrottled $clean_bytes); tbf dropped $(tc -s qdisc show dev lo | grep -o 'dropped [0-9]*' | cut -d' ' -f2) packets"
