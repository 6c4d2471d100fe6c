#pragma once
// What the Tables I-III harness computes (paper_examples/cerone_tables): which realisations, horizons and
// relaxation orders, where outer intervals are run (they cost minutes to hours; inner hulls cost seconds to
// minutes), and the engine's settings.
#include <cstdint>
#include <string>
#include <vector>

#include "dss/set_membership.hpp"
#include "paper_examples/cerone/equivalent_snr.hpp"
#include "paper_examples/cerone/inner_hull.hpp"

namespace hw::cerone {

struct TablesOptions {
  std::vector<int> horizons{2, 3};
  std::vector<int> orders{2, 3};        // the tables' outer-interval columns
  std::vector<int> outer_orders{2, 3};  // the columns actually computed (a subset of `orders`)
  std::vector<double> snrs{31, 35, 40, 45};  // SNR_w in dB: each sets the noise bound of a realisation
  std::vector<double> outer_snrs{31, 35, 40, 45};  // where outer intervals are computed (a subset of `snrs`)
  std::vector<uint64_t> seeds{1, 2, 3};
  int samples = 1000;
  std::vector<std::string> params;  // parameters in the tables (names); empty = all eight
  double box = 10.0;                // prior box [-box, box]^8, as in the paper
  // D^ss(n) lies inside D^ss(n-1) (its rows are a superset; Property 4), so the outer intervals of a shorter
  // horizon of the same realisation bound the longer one's set too: the longer horizon's engine runs start in
  // that box instead of the prior box (better conditioned LMIs, fewer live orthants). Property 4 then holds by
  // construction for the outer intervals; it stays a real check with nest_horizons off.
  bool nest_horizons = true;
  double tolerance = 1e-6;          // of the property checks (relative, table_properties.hpp)
  InnerHullOptions inner;
  // The engine's settings (solver, threads, run_dir, generation.block_order_cap, verification, ...); the order
  // and parameters are set per run, and run_dir gets one subdirectory per run.
  dss::BoundsOptions bounds;
  bool equivalent_snr = false;
  EquivalentSnrOptions equivalent;
  uint64_t equivalent_seed = 1;
  bool IsValid(std::string* error) const;
  // Whether the outer interval of this order is computed at this horizon and SNR (never below the horizon's
  // minimal order).
  bool outer_wanted(int order, int horizon, double snr) const;
};

// Comma lists as the command line gives them; false with a message naming `option` on a bad entry.
bool ParseIntList(const std::string& text, const std::string& option, std::vector<int>* out, std::string* error);
bool ParseDoubleList(const std::string& text, const std::string& option, std::vector<double>* out, std::string* error);
bool ParseSeedList(const std::string& text, const std::string& option, std::vector<uint64_t>* out, std::string* error);

}  // namespace hw::cerone
