#!/usr/bin/env bash
# marsala-monitor export DIR --mcap FILE (docs/runtime.md#mcap-export) read back by an independent reader: the MCAP
# library from npm (@mcap/core, pinned, installed once into the build folder's npm-mcap/, outside the build's inputs)
# reads the export of a ramp run of 3 agents (run inside run_isolated.sh's namespace) with mcap_check.js: both of its
# readers, every message against its embedded schema, the counts, the first and last terrains against the run's .asc
# files, the last poses against summary.json. Then the bad inputs: an existing target, a missing folder, a log that
# fails its checksums: exit 2, one line naming it, nothing written. The same run's summary.json carries the material
# score, which marsala-monitor summary prints. 77 = skipped without node/npm or when npm cannot
# install the reader (no network).
# Usage: mcap_export_test.sh DOMAIN
set -euo pipefail
case_name=mcap
domain="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=lib.sh
. "$here/lib.sh"
test_workspace export
command -v node >/dev/null && command -v npm >/dev/null || { echo "SKIP: node or npm is not installed"; exit 77; }
modules="${MARSALA_BUILD_DIR:-$root/build}/npm-mcap"
if [ ! -f "$modules/node_modules/@mcap/core/package.json" ]; then
  mkdir -p "$modules"
  npm install --prefix "$modules" --no-audit --no-fund --silent @mcap/core@2.2.2 >"$work/npm.log" 2>&1 ||
    { tail -3 "$work/npm.log"; echo "SKIP: npm could not install @mcap/core"; exit 77; }
fi
monitor="$bin/marsala-monitor"

sh "$here/run_isolated.sh" "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 3 \
  --dds cyclone --domain "$domain" --out "$work/run" --timeout 120 --quiet >"$work/spawn.log" 2>&1 ||
  { tail -20 "$work/spawn.log"; fail "spawn.sh ramp 3"; }

# The material score of the real run (docs/runtime.md#material-score): deposited is the run's volume, the ratio is
# deposited / needed, nothing off the ramps, and the need is the three wedges: 1.5 m high, 1.5 / kappa = 5 m long, the
# 1 m band 11 cells (1.1 m) wide, 3 x 1.5 x 5 / 2 x 1.1 = 12.375 m^3 as a continuous wedge (within 3 %: the cells).
python3 - "$work/run/summary.json" <<'PY' || fail "summary.json's material block"
import json, sys
s = json.load(open(sys.argv[1]))
m = s["material"]
assert m["deposited_m3"] == s["deposited_volume_m3"], m
assert abs(m["ratio"] - m["deposited_m3"] / m["needed_m3"]) <= 1e-12, m
assert abs(m["needed_m3"] - 12.375) <= 0.03 * 12.375, m
assert m.get("off_band_m3", 0) <= 1e-9, m
print(f"ok: material {m['deposited_m3']:.3f} of {m['needed_m3']:.3f} m3 needed, ratio {m['ratio']:.3f}")
PY
"$monitor" summary "$work/run" | grep -q '^  material .* of .* m3 needed: ratio ' || fail "monitor summary: no material line"

started=$(date +%s.%N)
"$monitor" export "$work/run" --mcap "$work/run.mcap" --every 50 >"$work/export.log" || fail "export: $(cat "$work/export.log")"
grep -q '^exported .* terrains, .* robot updates, .* events' "$work/export.log" || fail "export said '$(cat "$work/export.log")'"
node "$here/mcap_check.js" "$modules/node_modules" "$work/run.mcap" "$work/run" 50 || fail "the npm reader disagrees"
took=$(python3 -c "import time; print(round(time.time() - $started, 1))")
echo "ok: exported and read back in ${took} s: $(cat "$work/export.log")"

# bad ARGS... PATTERN: exit 2, one line on stderr matching PATTERN, nothing under $work/bad.mcap (nor its .tmp)
bad() {
  local pattern="${*: -1}" code=0
  "$monitor" export "${@:1:$#-1}" >/dev/null 2>"$work/err" || code=$?
  [ "$code" = 2 ] || fail "export ${*:1:$#-1}: exit $code, not 2"
  [ "$(wc -l <"$work/err")" = 1 ] && grep -q -- "$pattern" "$work/err" || fail "export ${*:1:$#-1}: said '$(cat "$work/err")'"
  [ ! -e "$work/bad.mcap" ] && [ ! -e "$work/bad.mcap.tmp" ] || fail "export ${*:1:$#-1} left a file behind"
}
before=$(sha256sum <"$work/run.mcap")
bad "$work/run" --mcap "$work/run.mcap" "run.mcap: exists"
[ "$(sha256sum <"$work/run.mcap")" = "$before" ] || fail "an existing target was changed"
bad "$work/none" --mcap "$work/bad.mcap" "none: no such run folder"
cp -r "$work/run" "$work/torn"
truncate -s -3 "$work/torn/run.log"  # a torn last record: its checksum fails
bad "$work/torn" --mcap "$work/bad.mcap" "torn/run.log.*damaged log is not exported"
echo "ok: an existing target, a missing folder and a damaged log exit 2 with one line and write nothing"
