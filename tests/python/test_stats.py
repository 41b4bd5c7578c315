"""marsala_tools.stats against values worked out by hand."""

import math

import pytest

from marsala_tools import stats


def test_spread_of_a_sample():
    # mean 40 / 8 = 5; squared deviations 9+1+1+1+0+0+4+16 = 32, sample variance 32 / 7.
    s = stats.spread([2, 4, 4, 4, 5, 5, 7, 9])
    assert s.n == 8
    assert s.mean == 5.0
    assert s.sd == pytest.approx(math.sqrt(32 / 7), rel=1e-15)
    assert (s.min, s.max) == (2.0, 9.0)


def test_spread_of_one_value_has_no_deviation():
    s = stats.spread([3.5])
    assert (s.n, s.mean, s.sd, s.min, s.max) == (1, 3.5, 0.0, 3.5, 3.5)


def test_spread_of_nothing_is_nan():
    s = stats.spread([])
    assert s.n == 0
    assert all(math.isnan(v) for v in (s.mean, s.sd, s.min, s.max))


def test_spread_takes_a_generator():
    s = stats.spread(x / 10 for x in (2, 5))  # 0.2 and 0.5: mean 0.35, sd 0.3 / sqrt(2)
    assert s.mean == pytest.approx(0.35, rel=1e-15)
    assert s.sd == pytest.approx(0.3 / math.sqrt(2), rel=1e-15)
