"""marsala_tools.search_routes: its command line and the cell centres of its candidate grid."""

import pytest

from marsala_tools import common, search_routes


def test_windows_and_defaults():
    a = search_routes.build_parser().parse_args(["--dem", "d.asc", "--windows", "0,0 94.5,-1"])
    assert a.windows == [(0.0, 0.0), (94.5, -1.0)]
    assert (a.size, a.cell_size, a.min_sites, a.rank, a.top, a.json) == (160.0, 0.25, 3, "volume", 15, None)
    assert len(search_routes.build_parser().parse_args(["--dem", "d"]).windows) == 10


@pytest.mark.parametrize("argv, message", [
    ([], "required: --dem"),
    (["--dem", "d", "--windows", "1,2,3"], "argument --windows: expects X0,Y0 pairs"),
    (["--dem", "d", "--windows", "a,b"], "expects X0,Y0 pairs"),
    (["--dem", "d", "--rank", "size"], "invalid choice: 'size'"),
    (["--dem", "d", "--min-sites", "0"], "argument --min-sites: '0' is not an integer"),
])
def test_argument_errors(argv, message):
    with pytest.raises(common.UsageError, match=message):
        search_routes.build_parser().parse_args(argv)


def test_a_missing_dem_is_a_usage_error(capsys):
    assert search_routes.main(["--dem", "/none/dem.asc"]) == 2
    assert capsys.readouterr().err == "search_routes: terrain file '/none/dem.asc' not found\n"


@pytest.mark.parametrize("v, centre", [(0.0, 0.125), (0.3, 0.375), (-0.1, -0.125), (10.25, 10.375)])
def test_centre_of_the_cell(v, centre):
    assert search_routes.centre(v, 0.0, 0.25) == centre
