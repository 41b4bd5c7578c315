#!/usr/bin/env python3
"""The scalability sweep (paper Fig. 5); the program is deploy/marsala_tools/sweep.py. Usage: deploy/sweep.sh --help"""

import sys

from marsala_tools import sweep

if __name__ == "__main__":
    sys.exit(sweep.main(sys.argv[1:]))
