#!/usr/bin/env bash
# One-parameter experiments live in deploy/experiment.py; usage: deploy/experiment.sh --help
exec python3 "$(dirname "${BASH_SOURCE[0]}")/experiment.py" "$@"
