#!/usr/bin/env python3
"""Route search on a DEM; the program is deploy/marsala_tools/search_routes.py. Usage: deploy/search_routes.py --help"""

import sys

from marsala_tools import search_routes

if __name__ == "__main__":
    sys.exit(search_routes.main(sys.argv[1:]))
