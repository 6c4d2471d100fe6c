#include "paper_examples/cerone/tables_options.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dss/hw_outer_set.hpp"

namespace hw::cerone {

namespace {

bool Fail(std::string* error, std::string message) {
  *error = std::move(message);
  return false;
}

// Splits "a,b,c" and converts each entry with `parse` (which throws or leaves characters on a bad entry).
template <class T, class Parse>
bool ParseList(const std::string& text, const std::string& option, std::vector<T>* out, std::string* error,
               const Parse& parse) {
  out->clear();
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    try {
      const T value = parse(item, &used);
      if (used != item.size()) throw std::invalid_argument(item);
      out->push_back(value);
    } catch (const std::exception&) {
      return Fail(error, fmt::format("{}: '{}' is not a number (give a comma list, e.g. {} 2,3)", option, item, option));
    }
  }
  if (out->empty()) return Fail(error, fmt::format("{}: the list is empty", option));
  return true;
}

template <class T>
bool IsSubset(const std::vector<T>& part, const std::vector<T>& whole) {
  return std::all_of(part.begin(), part.end(),
                     [&](const T& v) { return std::find(whole.begin(), whole.end(), v) != whole.end(); });
}

bool ValidSnrs(const std::vector<double>& snrs, const std::string& what, std::string* error) {
  for (double snr : snrs)
    if (!(std::isfinite(snr) && snr > 0 && snr <= 200))
      return Fail(error, fmt::format("{}: SNR {} dB is out of range (0, 200]", what, snr));
  return true;
}

bool ValidRuns(const TablesOptions& o, std::string* error) {
  for (int n : o.horizons)
    if (!dss::ValidHorizon(n, error)) return false;
  if (o.samples < 10 * (o.horizons.empty() ? 1 : *std::max_element(o.horizons.begin(), o.horizons.end())))
    return Fail(error, fmt::format("samples: N = {} is too small for the horizons (at least 10 n)", o.samples));
  // An order below a horizon's minimal order is skipped at that horizon; it must suit the shortest one.
  const int shortest = *std::min_element(o.horizons.begin(), o.horizons.end());
  for (int d : o.orders)
    if (!dss::ValidOrder(d, shortest, error)) return Fail(error, fmt::format("--orders: {}", *error));
  if (!IsSubset(o.outer_orders, o.orders)) return Fail(error, "--outer-orders: every order must be one of --orders");
  if (!ValidSnrs(o.snrs, "--snr-list", error) || !ValidSnrs(o.outer_snrs, "--outer-snr", error)) return false;
  if (!IsSubset(o.outer_snrs, o.snrs)) return Fail(error, "--outer-snr: every SNR must be one of --snr-list");
  if (o.seeds.empty()) return Fail(error, "--seeds: give at least one seed");
  return true;
}

}  // namespace

bool ParseIntList(const std::string& text, const std::string& option, std::vector<int>* out, std::string* error) {
  return ParseList<int>(text, option, out, error, [](const std::string& s, std::size_t* used) { return std::stoi(s, used); });
}

bool ParseDoubleList(const std::string& text, const std::string& option, std::vector<double>* out, std::string* error) {
  return ParseList<double>(text, option, out, error,
                           [](const std::string& s, std::size_t* used) { return std::stod(s, used); });
}

bool ParseSeedList(const std::string& text, const std::string& option, std::vector<uint64_t>* out, std::string* error) {
  return ParseList<uint64_t>(text, option, out, error, [](const std::string& s, std::size_t* used) {
    if (!s.empty() && s[0] == '-') throw std::invalid_argument(s);
    return static_cast<uint64_t>(std::stoull(s, used));
  });
}

bool TablesOptions::IsValid(std::string* error) const {
  if (horizons.empty() || orders.empty()) return Fail(error, "--horizons and --orders need at least one value");
  if (!ValidRuns(*this, error)) return false;
  const auto names = dss::MakeLayout(dss::CeroneExampleStructure()).names;
  for (const auto& p : params)
    if (std::find(names.begin(), names.end(), p) == names.end())
      return Fail(error, fmt::format("--params: unknown parameter '{}' (one of {})", p, fmt::join(names, ", ")));
  if (!(std::isfinite(box) && box > 0)) return Fail(error, "--box must be a positive number");
  if (!(tolerance >= 0 && tolerance < 1e-2)) return Fail(error, "--tolerance must be in [0, 1e-2)");
  if (!inner.IsValid(error)) return false;
  if (!equivalent.IsValid(error)) return false;
  dss::BoundsOptions check = bounds;
  check.order = outer_orders.empty() ? 2 : outer_orders.front();
  return check.IsValid(error);
}

bool TablesOptions::outer_wanted(int order, int horizon, double snr) const {
  return order >= dss::MinimalOrder(horizon) && std::count(outer_orders.begin(), outer_orders.end(), order) &&
         std::count(outer_snrs.begin(), outer_snrs.end(), snr);
}

}  // namespace hw::cerone
