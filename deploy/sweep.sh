#!/usr/bin/env bash
# The scalability sweep (paper Fig. 5) lives in deploy/sweep.py; this wrapper keeps `deploy/sweep.sh ...` working with
# the same arguments, outputs, messages and exit codes. Usage: deploy/sweep.sh --help
MARSALA_SWEEP_PROG=sweep.sh exec python3 "$(dirname "${BASH_SOURCE[0]}")/sweep.py" "$@"
