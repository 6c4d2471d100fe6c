#include "paper_examples/cerone/table_case.hpp"

#include <fmt/format.h>

namespace hw::cerone {

std::string TableCase::label() const {
  return fmt::format("n={}, {:g} dB, seed {}, N={}", horizon, snr_db, seed, samples);
}

const dss::ParameterInterval* FindInterval(const dss::BoundsSummary& run, const std::string& name) {
  for (const auto& iv : run.intervals)
    if (iv.name == name) return &iv;
  return nullptr;
}

}  // namespace hw::cerone
