"""Statistics of a sample of runs through the statistics module."""

import math
import statistics
from dataclasses import dataclass


@dataclass
class Spread:
    """Count, mean, sample standard deviation (n - 1; 0 for one value), minimum and maximum of a sample; NaN for
    each but the count when the sample is empty."""

    n: int
    mean: float
    sd: float
    min: float
    max: float


def spread(values):
    """The Spread of a sample of numbers."""
    values = [float(v) for v in values]
    if not values:
        return Spread(0, math.nan, math.nan, math.nan, math.nan)
    sd = statistics.stdev(values) if len(values) > 1 else 0.0
    return Spread(len(values), statistics.fmean(values), sd, min(values), max(values))
