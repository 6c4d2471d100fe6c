#pragma once
// One case of the tables: a realisation of the paper-001 example (SNR, seed, N) at one dynamic horizon n, with
// its inner hull and the outer intervals of the relaxation orders that were run.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "dss/set_membership.hpp"
#include "paper_examples/cerone/inner_hull.hpp"

namespace hw::cerone {

struct TableCase {
  int horizon = 2;
  double snr_db = 31.0;           // as asked (sets the noise bound)
  double realised_snr_db = 0.0;   // of the realisation
  double noise_bound = 0.0;
  uint64_t seed = 1;
  int samples = 1000;
  std::vector<std::string> names;  // every parameter of the layout
  std::vector<double> truth;       // in layout order
  InnerHull inner;                 // the wanted parameters
  std::map<int, dss::BoundsSummary> outer;  // relaxation order -> the engine's run (wanted parameters)
  // The box the outer runs started in: the prior box, or the outer intervals of horizon `box_from_horizon`.
  std::vector<std::pair<double, double>> outer_box;
  int box_from_horizon = 0;  // 0: the prior box
  // "n=2, 31 dB, seed 1": for messages.
  std::string label() const;
};

// The interval of parameter `name` in a run, or null.
const dss::ParameterInterval* FindInterval(const dss::BoundsSummary& run, const std::string& name);

}  // namespace hw::cerone
