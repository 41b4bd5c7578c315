#!/bin/sh
# Runs a command inside a private network namespace in which only loopback is up, so DDS traffic cannot leave the
# host even with a wrong config (a second fence besides deploy/dds/*-lo.xml). Needs root or unprivileged user
# namespaces; when unshare is not permitted it runs the command directly, with a notice.
# Usage: run_isolated.sh COMMAND [ARGS...]
if [ $# -eq 0 ]; then
  echo "usage: run_isolated.sh COMMAND [ARGS...]" >&2
  exit 2
fi
if command -v unshare >/dev/null 2>&1 && command -v ip >/dev/null 2>&1 && unshare -n true 2>/dev/null; then
  exec unshare -n sh -c 'ip link set lo up || { echo "run_isolated: cannot bring lo up" >&2; exit 1; }; exec "$@"' \
    run_isolated "$@"
fi
echo "run_isolated: notice: no private network namespace here (unshare -n not permitted); running directly" >&2
exec "$@"
