#!/usr/bin/env python3
"""One-parameter experiments; the program is deploy/marsala_tools/experiment.py. Usage: deploy/experiment.sh --help"""

import sys

from marsala_tools import experiment

if __name__ == "__main__":
    sys.exit(experiment.main(sys.argv[1:]))
