// The MARS and navigability processors against their brute-force references on terrains of every generator.
#include <gtest/gtest.h>

#include <string>

#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/terrain/generators.hpp"
#include "support/mars_brute_force.hpp"
#include "support/navigability_brute_force.hpp"

namespace marsala {
namespace {

struct Case {
  std::string method;
  std::uint64_t seed;
};

std::vector<Case> all_cases() {
  std::vector<Case> cases;
  for (const std::string& method : terrain::generator_names())
    for (std::uint64_t seed : {1u, 2u, 3u}) cases.push_back({method, seed});
  return cases;
}

class ProcessorsOnGenerators : public ::testing::TestWithParam<Case> {
 protected:
  Heightmap terrain(int rows, int cols, double cs) const {
    terrain::GeneratorSpec spec;
    spec.rows = rows;
    spec.cols = cols;
    spec.cell_size_m = cs;
    spec.seed = GetParam().seed;
    return terrain::generate_terrain(GetParam().method, spec);
  }
};

TEST_P(ProcessorsOnGenerators, MarsMatchesBruteForce) {
  for (const double kappa : {0.1, 0.3, 1.0}) {
    const Heightmap h = terrain(37, 45, 0.1);
    const Heightmap fast = MarsProcessor(kappa).project(h);
    const Heightmap brute = testing::mars_brute_force(h, kappa);
    ASSERT_EQ(fast.rows(), brute.rows());
    EXPECT_LE((fast.heights() - brute.heights()).cwiseAbs().maxCoeff(), 1e-9) << "kappa " << kappa;
    // Fed back, the projection must not move (idempotence) and must still match brute force.
    const Heightmap again = MarsProcessor(kappa).project(fast);
    EXPECT_LE((again.heights() - fast.heights()).cwiseAbs().maxCoeff(), 1e-9) << "kappa " << kappa;
  }
}

TEST_P(ProcessorsOnGenerators, NavigabilityMatchesBruteForce) {
  const Heightmap h = terrain(33, 41, 0.1);
  for (const NavigabilityParams params :
       {NavigabilityParams{0.3, 0.6, 0.05}, NavigabilityParams{0.5, 1.0, 0.02}, NavigabilityParams{0.2, 0.3, 0.0}}) {
    const NavigabilityProcessor processor(params);
    const CellMask fast = processor.occupiable(h);
    const CellMask brute = testing::occupiable_brute_force(h, params);
    EXPECT_TRUE(fast == brute) << "kappa " << params.kappa << " delta " << params.delta_m << " eps " << params.eps_m;
    const CellIndex origin{h.rows() / 2, h.cols() / 2};
    EXPECT_TRUE(processor.navigable(h, origin) == testing::navigable_brute_force(h, params, origin));
  }
}

INSTANTIATE_TEST_SUITE_P(EveryGenerator, ProcessorsOnGenerators, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                           return param_info.param.method + "_seed" + std::to_string(param_info.param.seed);
                         });

}  // namespace
}  // namespace marsala
