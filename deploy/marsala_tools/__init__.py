"""MARSala's run tools: the scalability sweep, one-parameter experiments and the route search, over one runner.

Modules: common (errors, argument types, the build's binaries, marsala-world --check), runner (spawn.sh jobs run in
parallel, a fresh DDS domain each), summary (a run's summary.json), tables (CSV files through the csv module), stats
(mean, sd, min, max through the statistics module); sweep, experiment and search_routes are the programs, each with an
argparse front end (`main(argv)`), run by the thin scripts deploy/sweep.py, deploy/experiment.py and
deploy/search_routes.py. Standard library only (Debian's python3).
"""
