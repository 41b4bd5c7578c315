# Shell helpers shared by the integration test scripts (sourced, not run).
# field NAME FILE: the first scalar NAME of a summary.json
field() {
  grep -o "\"$1\": *[^,}]*" "$2" | head -1 | sed 's/^[^:]*: *//; s/"//g'
}
# csv_last CSV NAME: the column NAME (by the header's names) of the last row of CSV
csv_last() {
  awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == name) col = i } END { if (col) print $col }' "$1"
}
# is_png FILE: true when FILE starts with the PNG signature
is_png() { [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]; }
# test_workspace NAME, in a script that has set case_name and here (its folder): sets root, bin (MARSALA_BUILD_DIR's
# or build/'s), work (a temporary folder marsala_NAME_<case>.XXXXXX, removed at exit), fail MESSAGE (exit 1 naming
# the case), and the loopback Cyclone DDS configuration.
test_workspace() {
  root="$(cd "$here/../.." && pwd)"
  bin="${MARSALA_BUILD_DIR:-$root/build}/bin"
  work="$(mktemp -d "${TMPDIR:-/tmp}/marsala_$1_${case_name}.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
  fail() { echo "FAIL ($case_name): $*" >&2; exit 1; }
  export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
}
# bridge_hosts PREFIX COUNT, as root inside network and mount namespaces of the test's own: hosts h1..hCOUNT (network
# namespaces, lo up) joined by the bridge br0, host i at PREFIX.i/24 on its eth0 with multicast routed there, plugged
# into the bridge by port<i> (detach it, `ip link set port<i> nomaster`, to cut the host off). Exits 77 (skipped) where
# /run/netns cannot be mounted or bridges or veth pairs cannot be made.
bridge_hosts() {
  ip link set lo up
  mkdir -p /run/netns && mount -t tmpfs tmpfs /run/netns || { echo "SKIP: cannot mount /run/netns"; exit 77; }
  ip link add br0 type bridge 2>/dev/null || { echo "SKIP: cannot make a bridge here"; exit 77; }
  ip link set br0 up
  local i
  for i in $(seq 1 "$2"); do
    ip netns add "h$i"
    ip link add "port$i" type veth peer name eth0 netns "h$i" || { echo "SKIP: cannot make veth pairs here"; exit 77; }
    ip link set "port$i" master br0 up
    ip -n "h$i" link set lo up
    ip -n "h$i" addr add "$1.$i/24" dev eth0
    ip -n "h$i" link set eth0 up multicast on
    ip -n "h$i" route add 224.0.0.0/4 dev eth0
  done
}
# expect_tool_usage_error TOOL WORK PATTERN ARGS...: TOOL --out WORK/bad ARGS exits 2 with PATTERN on stderr and
# writes nothing (fail MESSAGE must be defined)
expect_tool_usage_error() {
  local tool="$1" work="$2" pattern="$3" rc=0
  shift 3
  "$tool" --out "$work/bad" "$@" >"$work/stdout.txt" 2>"$work/stderr.txt" || rc=$?
  [ "$rc" -eq 2 ] || { cat "$work/stderr.txt"; fail "$(basename "$tool") $* exited $rc, expected 2"; }
  grep -q -- "$pattern" "$work/stderr.txt" || { cat "$work/stderr.txt"; fail "$(basename "$tool") $*: no '$pattern'"; }
  [ ! -e "$work/bad" ] || fail "$(basename "$tool") $* wrote $work/bad"
}
