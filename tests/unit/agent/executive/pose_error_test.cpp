// The localisation error model: its statistics against the Gauss-Markov process it claims to be, determinism, and
// bad specs.

#include "marsala/agent/executive/pose_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala::agent::executive {
namespace {

Localisation spec(double sd, double correlation_steps) {
  Localisation l;
  l.noise_sd_m = sd;
  l.correlation_steps = correlation_steps;
  return l;
}

TEST(PoseError, HasTheConfiguredSpreadAndCorrelationTime) {
  // 200,000 steps with tau = 20: about 5,000 independent samples per axis (N (1 - a) / (1 + a)), so the measured sd
  // lies within ~3 % of the configured one and the lag-tau autocorrelation within ~0.04 of exp(-1) (3 standard
  // errors; the seed is fixed, so the check is deterministic).
  const double sd = 0.1, tau = 20.0;
  PoseError error(spec(sd, tau), 42);
  std::vector<double> xs, ys;
  for (std::uint64_t step = 0; step < 200000; ++step) {
    const Position e = error.at(step);
    xs.push_back(e.x);
    ys.push_back(e.y);
  }
  for (const std::vector<double>* axis : {&xs, &ys}) {
    const std::vector<double>& v = *axis;
    double mean = 0.0, var = 0.0, lag = 0.0;
    for (double x : v) mean += x;
    mean /= v.size();
    for (double x : v) var += (x - mean) * (x - mean);
    var /= v.size();
    for (std::size_t i = 20; i < v.size(); ++i) lag += (v[i] - mean) * (v[i - 20] - mean);
    lag /= (v.size() - 20) * var;
    EXPECT_NEAR(mean, 0.0, 0.01);
    EXPECT_NEAR(std::sqrt(var), sd, 0.03 * sd);
    EXPECT_NEAR(lag, std::exp(-1.0), 0.04);
  }
  // The two axes are independent.
  double cross = 0.0, vx = 0.0, vy = 0.0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    cross += xs[i] * ys[i];
    vx += xs[i] * xs[i];
    vy += ys[i] * ys[i];
  }
  EXPECT_NEAR(cross / std::sqrt(vx * vy), 0.0, 0.05);
}

TEST(PoseError, DriftsByAtMostAFewDrivesPerStep) {
  // Consecutive errors differ by (1 - a) e + sqrt(1 - a^2) sd n: with tau = 50 and sd 0.2 m, |n| < 6 keeps every
  // step's change below 0.2 m * (0.02 * 5 + 0.2 * 6) ~ 0.26 m; a jump of a whole sd would break it.
  PoseError error(spec(0.2, 50.0), 7);
  Position last = error.at(0);
  const double a = std::exp(-1.0 / 50.0), drive = std::sqrt(1.0 - a * a) * 0.2;
  for (std::uint64_t step = 1; step < 5000; ++step) {
    const Position e = error.at(step);
    EXPECT_LT(std::abs(e.x - a * last.x), 6.0 * drive) << step;
    EXPECT_LT(std::abs(e.y - a * last.y), 6.0 * drive) << step;
    last = e;
  }
}

TEST(PoseError, IsTheSameForTheSameSeedWhicheverStepsWereAsked) {
  PoseError every(spec(0.05, 10.0), 3), some(spec(0.05, 10.0), 3), other(spec(0.05, 10.0), 4);
  std::vector<Position> all;
  for (std::uint64_t step = 5; step <= 60; ++step) all.push_back(every.at(step));
  // Started at the same step, a robot that missed steps 6-29 sees the same error at 30 and after.
  EXPECT_EQ(some.at(5).x, all[0].x);
  const Position at30 = some.at(30);
  EXPECT_EQ(at30.x, all[25].x);
  EXPECT_EQ(at30.y, all[25].y);
  EXPECT_EQ(some.at(30).x, at30.x);  // asking the same step again draws nothing
  EXPECT_EQ(some.at(60).y, all[55].y);
  EXPECT_NE(other.at(5).x, all[0].x);
  EXPECT_THROW(some.at(59), InvalidArgument);
}

TEST(PoseError, ZeroNoiseIsExactAndBadSpecsAreRefused) {
  PoseError exact(spec(0.0, 50.0), 1);
  EXPECT_FALSE(exact.active());
  for (std::uint64_t step = 0; step < 100; ++step) {
    EXPECT_EQ(exact.at(step).x, 0.0);
    EXPECT_EQ(exact.at(step).y, 0.0);
  }
  EXPECT_THROW(PoseError(spec(-0.1, 50.0), 1), InvalidArgument);
  EXPECT_THROW(PoseError(spec(std::nan(""), 50.0), 1), InvalidArgument);
  EXPECT_THROW(PoseError(spec(11.0, 50.0), 1), InvalidArgument);
  EXPECT_THROW(PoseError(spec(0.1, 0.5), 1), InvalidArgument);
  EXPECT_THROW(PoseError(spec(0.1, INFINITY), 1), InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::executive
