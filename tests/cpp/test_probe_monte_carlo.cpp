// SPDX-License-Identifier: BSD-3-Clause
// Tests of probe/monte_carlo.hpp on the independent implementation's touch-probe session
// (../shared/data/probe_ac_table2.csv, 0.5 um white noise): the draws scatter about the identified
// values (the touches are moved onto the identified machine) by the reported 1-sigma, and a fit
// that is not the joint fit of the session is refused.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "rotacal/core/error.hpp"
#include "rotacal/io/probe_file.hpp"
#include "rotacal/probe/monte_carlo.hpp"

using namespace rotacal;

TEST_CASE("the probe Monte Carlo scatters about the identified values by the reported sigma",
          "[probe][mc]") {
  const ProbeSession s = read_probe(std::string(ROTACAL_SHARED_DIR) + "/data/probe_ac_table2.csv");
  const ProbeIdentification id = identify_probe(s);
  ProbeMonteCarloOptions o;
  o.draws = 400;
  o.noise = NoiseHandling::white;
  const ProbeMonteCarlo mc = monte_carlo_probe(s, id, o);
  CHECK(mc.noise == "white noise");
  CHECK(mc.noise_um == id.sigma_um);
  REQUIRE(mc.parameters.size() ==
          id.parameters.size());  // 8 location errors and the sphere, all observable
  for (const MonteCarloParameter& p : mc.parameters) {
    INFO(p.name << ": ratio " << p.ratio << ", bias " << p.bias << ", std_mc " << p.std_mc);
    // 400 draws: the sample sigma is within ~3.5 % (1 sigma) of the truth.
    CHECK(p.ratio > 0.87);
    CHECK(p.ratio < 1.13);
    // The draws' mean is the identified value: the touches were moved onto the identified machine.
    CHECK(std::abs(p.bias) < 4.0 * p.std_mc / std::sqrt(400.0));
  }
}

TEST_CASE("the probe Monte Carlo refuses what is not the joint fit of the session", "[probe][mc]") {
  const ProbeSession s = read_probe(std::string(ROTACAL_SHARED_DIR) + "/data/probe_ac_table2.csv");
  CHECK_THROWS_AS(monte_carlo_probe(s, identify_probe_cycles(s)), InvalidArgument);
  ProbeMonteCarloOptions one;
  one.draws = 1;
  CHECK_THROWS_WITH(monte_carlo_probe(s, identify_probe(s), one),
                    Catch::Contains("draws must be at least 2"));
  ProbeSession fewer = s;
  fewer.samples.pop_back();
  CHECK_THROWS_AS(monte_carlo_probe(fewer, identify_probe(s)), InvalidArgument);
}
