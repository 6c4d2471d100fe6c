#include "paper_examples/cerone/tables_cli.hpp"

#include <algorithm>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace hw::cerone {

namespace {

// The command line as text options, converted and checked after parsing (one message per bad value).
struct CommandLine {
  std::string out = "out/cerone_tables", horizons = "2,3", orders = "2,3", outer_orders, snrs = "31,35,40,45",
              outer_snrs, seeds = "1,2,3", params, equivalent_range = "31,60", equivalent_seed;
};

void AddOptions(CLI::App& app, CommandLine& cl, TablesOptions& o) {
  app.add_option("--out", cl.out, "output directory")->capture_default_str();
  app.add_option("--horizons", cl.horizons, "dynamic horizons n, comma list")->capture_default_str();
  app.add_option("--orders", cl.orders, "relaxation orders delta of the outer-interval columns")->capture_default_str();
  app.add_option("--outer-orders", cl.outer_orders, "orders whose outer intervals are computed (default: --orders; 'none')");
  app.add_option("--snr-list", cl.snrs, "SNR_w values in dB (each sets the noise bound)")->capture_default_str();
  app.add_option("--outer-snr", cl.outer_snrs, "SNRs at which outer intervals are computed (default: --snr-list; 'none')");
  app.add_option("--seeds", cl.seeds, "realisation seeds")->capture_default_str();
  app.add_option("--samples", o.samples, "N")->capture_default_str();
  app.add_option("--params", cl.params, "only these parameters, comma list (default: all)");
  app.add_option("--solver", o.bounds.solver, "SDP backend: auto, csdp, sdpa or dsdp")->capture_default_str();
  app.add_option("--threads", o.bounds.threads, "parallel SDP jobs (0 = one per core)")->capture_default_str();
  app.add_option("--run-dir", o.bounds.run_dir, "resumable cache of finished SDPs, a subdirectory per run ('' = none)")
      ->capture_default_str();
  app.add_option("--row-block-order", o.bounds.generation.block_order_cap,
                 "localizing order of the data rows' blocks at most (-1: full; 1 at order 3: the mixed relaxation)")
      ->capture_default_str();
  app.add_option("--contract-passes", o.bounds.contraction_passes, "cheap passes in contracted boxes (0 = off)");
  app.add_option("--endpoint-refinements", o.bounds.endpoint_refinements,
                 "times every open endpoint is solved again at full order in the box of the full pass's own bounds "
                 "(0 = never)")
      ->check(CLI::Range(0, hw::dss::kMaxEndpointRefinements))
      ->capture_default_str();
  app.add_flag("--nest-horizons,!--no-nest-horizons", o.nest_horizons,
               "start each horizon's outer runs in the box of the shorter horizon's outer intervals (default on)");
  app.add_flag("--verify,!--no-verify", o.bounds.generation.verify.enabled, "verify every endpoint (default on)");
  app.add_option("--inner-starts", o.inner.random_starts, "pseudo-random starts per objective of the inner hull")
      ->capture_default_str();
  app.add_option("--inner-restarts", o.inner.restart_rounds, "restart rounds from other objectives' witnesses")
      ->capture_default_str();
  app.add_option("--tolerance", o.tolerance, "relative tolerance of the property checks")->capture_default_str();
  app.add_flag("--equivalent-snr", o.equivalent_snr, "find the SNR at which the inner hulls match the paper's widths");
  app.add_option("--equivalent-range", cl.equivalent_range, "LOW,HIGH dB of that bisection")->capture_default_str();
  app.add_option("--equivalent-iterations", o.equivalent.iterations, "bisection steps")->capture_default_str();
  app.add_option("--equivalent-seed", cl.equivalent_seed, "seed of that bisection (default: the first of --seeds)");
}

// A list option that may be 'none' (nothing computed) or unset (= `fallback`).
template <class T, class Parse>
bool ParseSubset(const std::string& text, const std::string& fallback, const std::string& option, std::vector<T>* out,
                 std::string* error, const Parse& parse) {
  if (text == "none") return out->clear(), true;
  return parse(text.empty() ? fallback : text, option, out, error);
}

bool ConvertOptions(const CommandLine& cl, TablesOptions& o, std::string* error) {
  if (!ParseIntList(cl.horizons, "--horizons", &o.horizons, error) || !ParseIntList(cl.orders, "--orders", &o.orders, error) ||
      !ParseSubset(cl.outer_orders, cl.orders, "--outer-orders", &o.outer_orders, error, ParseIntList) ||
      !ParseDoubleList(cl.snrs, "--snr-list", &o.snrs, error) ||
      !ParseSubset(cl.outer_snrs, cl.snrs, "--outer-snr", &o.outer_snrs, error, ParseDoubleList) ||
      !ParseSeedList(cl.seeds, "--seeds", &o.seeds, error))
    return false;
  std::vector<double> range;
  if (!ParseDoubleList(cl.equivalent_range, "--equivalent-range", &range, error)) return false;
  if (range.size() != 2) return *error = "--equivalent-range: give LOW,HIGH", false;
  o.equivalent.low_db = range[0];
  o.equivalent.high_db = range[1];
  std::vector<uint64_t> seed{o.seeds.front()};
  if (!cl.equivalent_seed.empty() && !ParseSeedList(cl.equivalent_seed, "--equivalent-seed", &seed, error)) return false;
  o.equivalent_seed = seed.front();
  o.params.clear();
  for (std::size_t begin = 0; !cl.params.empty() && begin <= cl.params.size();) {
    const std::size_t end = std::min(cl.params.find(',', begin), cl.params.size());
    o.params.push_back(cl.params.substr(begin, end - begin));
    begin = end + 1;
  }
  return o.IsValid(error);
}

}  // namespace

int ParseTablesCommand(const std::vector<std::string>& args, TablesCommand* command, std::string* message) {
  CLI::App app{"Tables I-III of Cerone, Piga, Regruto: outer intervals, inner hulls, the paper's intervals"};
  CommandLine cl;
  TablesOptions options;
  options.bounds.run_dir = "runs/cerone_tables";
  AddOptions(app, cl, options);
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes the arguments last first
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    *message = app.help();
    return 1;
  } catch (const CLI::ParseError& e) {
    *message = e.what();
    return 2;
  }
  if (!ConvertOptions(cl, options, message)) return 2;
  command->options = options;
  command->out = cl.out;
  command->text = "cerone_tables";
  for (const auto& a : args) command->text += " " + a;
  return 0;
}

}  // namespace hw::cerone
