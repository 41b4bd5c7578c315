# Shell helpers shared by the integration test scripts (sourced, not run).
# field NAME FILE: the first scalar NAME of a summary.json
field() {
  grep -o "\"$1\": *[^,}]*" "$2" | head -1 | sed 's/^[^:]*: *//; s/"//g'
}
# is_png FILE: true when FILE starts with the PNG signature
is_png() { [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]; }
