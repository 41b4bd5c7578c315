#!/usr/bin/env bash
# The scalability sweep (paper Fig. 5), deploy/marsala_tools/sweep.py. Usage: deploy/sweep.sh --help
exec python3 "$(dirname "${BASH_SOURCE[0]}")/sweep.py" "$@"
