#!/usr/bin/env bash
# One-parameter experiments, deploy/marsala_tools/experiment.py. Usage: deploy/experiment.sh --help
exec python3 "$(dirname "${BASH_SOURCE[0]}")/experiment.py" "$@"
