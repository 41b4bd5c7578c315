# Shell helpers shared by the integration test scripts (sourced, not run).
# field NAME FILE: the first scalar NAME of a summary.json
field() {
  grep -o "\"$1\": *[^,}]*" "$2" | head -1 | sed 's/^[^:]*: *//; s/"//g'
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
