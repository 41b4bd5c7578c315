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
