#!/usr/bin/env bash
# The image's entrypoint (docker/entrypoint.sh) gives Fast DDS teams of 48 agents or more the crowd's timing, as
# deploy/spawn.sh does: the DDS profile each role starts with, read by stub programs on PATH (no DDS, no container).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-entrypoint.XXXXXX")"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin" "$work/dds"
for p in marsala-world marsala-agent marsala-monitor; do
  printf '#!/bin/sh\necho "%s ${MARSALA_DDS_CONFIG:-none}"\n' "$p" >"$work/bin/$p"
  chmod +x "$work/bin/$p"
done
cp "$root"/deploy/dds/*.xml "$root"/deploy/dds/crowd.sh "$work/dds/"
fail=0
# check ROLE DDS AGENTS CONFIG EXPECTED: the profile ROLE runs with, unsecured
check() {
  local got
  got=$(env PATH="$work/bin:$PATH" MARSALA_INSECURE=1 MARSALA_DDS="$2" MARSALA_AGENTS="$3" \
        MARSALA_DDS_CONFIG="$4" bash "$root/docker/entrypoint.sh" "$1" 2>"$work/stderr")
  if [ "$got" != "marsala-$1 $5" ]; then
    echo "FAIL: $1, $2, $3 agents, $4: got '$got', expected 'marsala-$1 $5'"; cat "$work/stderr"; fail=1
  elif [ "$4" != "$5" ] && ! grep -q "the crowd's timing, $5" "$work/stderr"; then
    echo "FAIL: $1, $2, $3 agents: the change to $5 is not said on stderr"; cat "$work/stderr"; fail=1
  fi
}
d="$work/dds"
check agent fastdds 60 "$d/fastdds-unicast.xml" "$d/fastdds-unicast-crowd.xml"
check world fastdds 240 "$d/fastdds-unicast.xml" "$d/fastdds-unicast-crowd.xml"
check monitor fastdds 48 "$d/fastdds-lo.xml" "$d/fastdds-crowd.xml"
check agent fastdds 47 "$d/fastdds-unicast.xml" "$d/fastdds-unicast.xml"       # below the crowd: as given
check agent cyclone 60 "$d/cyclone-unicast.xml" "$d/cyclone-unicast.xml"       # Cyclone needs no other timing
check agent fastdds 60 "$d/fastdds-lan.xml" "$d/fastdds-lan.xml"               # no crowd twin: as given
cp "$d/fastdds-unicast.xml" "$work/mine.xml"
check agent fastdds 60 "$work/mine.xml" "$work/mine.xml"                       # a user's own profile: as given
mkdir "$work/other" && cp "$d/fastdds-unicast.xml" "$d/fastdds-unicast-crowd.xml" "$work/other/"
check agent fastdds 60 "$work/other/fastdds-unicast.xml" "$work/other/fastdds-unicast.xml"  # no rule (crowd.sh) beside
rm "$d/fastdds-unicast-crowd.xml"
check agent fastdds 60 "$d/fastdds-unicast.xml" "$d/fastdds-unicast.xml"       # an image without the twin: as given
[ "$fail" -eq 0 ] && echo "ok: the entrypoint gives Fast DDS teams of 48 or more the crowd's profiles, nothing else"
exit "$fail"
