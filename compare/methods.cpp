#include "compare/methods.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "dss/set_membership.hpp"
#include "exact/exact_bounds.hpp"
#include "exact/two_stage.hpp"
#include "estimators/brouri/workflow.hpp"
#include "estimators/esmaeilani/estimator.hpp"
#include "estimators/esmaeilani/valve_case.hpp"
#include "sdp/job_executor.hpp"

namespace hw::compare {

std::string ToString(MethodStatus status) { return status == MethodStatus::kOk ? "ok" : "failed"; }

MethodStatus MethodStatusOf(const nlohmann::json& record) {
  return record.value("status", "") == ToString(MethodStatus::kOk) ? MethodStatus::kOk : MethodStatus::kFailed;
}
namespace {

using nlohmann::json;
constexpr double kPi = 3.14159265358979323846;

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<double> Linspace(double lo, double hi, int n) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = lo + (hi - lo) * i / (n - 1);
  return v;
}
std::vector<double> OmegaGrid() {
  std::vector<double> w;
  for (int k = 1; k <= 100; ++k) w.push_back(kPi * k / 100.0);
  return w;
}

// Static curve, normalised frequency response and validation fit of `est` against `truth`.
void DiscreteQuantities(const Scenario& s, const Plant& truth, const Plant& est, const Record& val, json* out) {
  json& q = (*out)["quantities"];
  json& na = (*out)["not_available"];
  json& curves = (*out)["curves"];
  const auto u = Linspace(s.input_lo, s.input_hi, 101);
  std::vector<double> yt, ye;
  bool ok = true;
  for (double v : u) {
    const auto a = truth.steady_state(v);
    const auto b = est.steady_state(v);
    if (!a || !b || !std::isfinite(*b)) {
      ok = false;
      break;
    }
    yt.push_back(*a);
    ye.push_back(*b);
  }
  if (ok && std::isfinite(est.static_gain()) && est.static_gain() != 0.0) {
    const auto [lo, hi] = std::minmax_element(yt.begin(), yt.end());
    const double range = std::max(*hi - *lo, 1e-300);
    double ss = 0.0, mx = 0.0;
    for (std::size_t i = 0; i < u.size(); ++i) {
      ss += (ye[i] - yt[i]) * (ye[i] - yt[i]);
      mx = std::max(mx, std::abs(ye[i] - yt[i]));
    }
    q["static_rms_pct"] = 100.0 * std::sqrt(ss / u.size()) / range;
    q["static_max_pct"] = 100.0 * mx / range;
    curves["static_u"] = u;
    curves["static_y"] = ye;
  } else {
    const std::string why = "the model's steady state is undefined (G(1) = 0 or no inverse of the output polynomial)";
    na["static_rms_pct"] = why;
    na["static_max_pct"] = why;
  }
  const auto w = OmegaGrid();
  std::vector<double> g;
  double mx = 0.0, ss = 0.0;
  for (double om : w) {
    const double ge = est.normalised_gain(om), gt = truth.normalised_gain(om);
    g.push_back(ge);
    mx = std::max(mx, std::abs(ge - gt));
    ss += (ge - gt) * (ge - gt);
  }
  // std::max drops NaN, so the sum is what shows an undefined response (e.g. a midpoint model with b = 0).
  if (std::isfinite(mx) && std::isfinite(ss)) {
    q["freq_max_error"] = mx;
    q["freq_rms_error"] = std::sqrt(ss / w.size());
    curves["omega"] = w;
    curves["gain"] = g;
  } else {
    na["freq_max_error"] = na["freq_rms_error"] = "G(1) = 0: the normalised response is undefined";
  }
  const auto yh = est.simulate(val.u);
  if (yh.size() == val.w.size()) q["fit_pct"] = fit_percent(val.w, yh);
  else na["fit_pct"] = "the model cannot be simulated on the validation record (output polynomial not invertible "
                       "along the trajectory)";
}

Plant PlantFromTheta(const SetMembershipClass& cls, const std::vector<double>& theta) {
  const auto layout = dss::MakeLayout(cls.structure);
  Plant p;
  std::vector<double> in = {1.0}, inv = {1.0};
  for (int k = 0; k < layout.num_gamma; ++k) in.push_back(theta[layout.gamma_begin + k]);
  for (int k = 0; k < layout.num_alpha; ++k) inv.push_back(theta[layout.alpha_begin + k]);
  p.model.input = StaticMap::Polynomial(in);
  p.inverse_output = inv;
  p.model.linear.a.assign(theta.begin() + layout.a_begin, theta.begin() + layout.a_begin + cls.structure.na);
  p.model.linear.b.clear();
  if (cls.structure.strictly_proper) p.model.linear.b.push_back(0.0);
  for (int k = layout.b_begin; k < layout.count(); ++k) p.model.linear.b.push_back(theta[k]);
  p.model.name = "setmembership_midpoint";
  return p;
}

// The prior box of the set-membership experiment (checked to hold the truth: the bounds assume it does).
std::vector<std::pair<double, double>> PriorBox(const Scenario& s, const SetMembershipClass& cls) {
  const auto& sm = s.setmembership;
  auto box = sm.box;
  if (box.empty()) box.assign(cls.names.size(), {-sm.box_half_width, sm.box_half_width});
  if (box.size() != cls.names.size())
    throw InputError(fmt::format("setmembership.box has {} intervals; the model has {} parameters ({})", box.size(),
                                 cls.names.size(), fmt::join(cls.names, ", ")));
  for (std::size_t k = 0; k < box.size(); ++k)
    if (!(box[k].first <= cls.theta[k] && cls.theta[k] <= box[k].second))
      throw InputError(fmt::format("setmembership.box: the true {} = {} lies outside the prior box [{}, {}]; the "
                                   "bounds assume the box contains the truth", cls.names[k], cls.theta[k],
                                   box[k].first, box[k].second));
  return box;
}

// The D^ss(n) run of the set-membership experiment on one record, in this process (runs are already spread over
// workers). Both set-membership methods report from it: the exact set starts in its box.
struct OuterSetRun {
  std::vector<std::pair<double, double>> box;
  dss::HwData data;
  dss::HwOuterSet set;
  dss::BoundsSummary summary;
};

OuterSetRun RunOuterSet(const Scenario& s, const SetMembershipClass& cls, const Record& rec, double bound) {
  const auto& sm = s.setmembership;
  const auto box = PriorBox(s, cls);
  dss::HwData data{rec.u, rec.y, std::vector<double>(rec.y.size(), bound), "compare run"};
  dss::HwOuterSet set(cls.structure, data, sm.horizon, box);
  dss::BoundsOptions o;
  o.order = sm.order;
  o.solver = sm.solver;
  o.parameters = sm.parameters;
  o.contraction_passes = sm.contract_passes;
  o.executor = std::make_shared<sdp::InProcessExecutor>();
  std::string err;
  if (!o.IsValid(&err)) throw InputError("setmembership options: " + err);
  dss::BoundsSummary summary = dss::ComputeBounds(o, set);
  return {box, std::move(data), std::move(set), std::move(summary)};
}

// One interval as the comparison reports it.
struct ReportedInterval {
  std::string name;
  double lower = 0.0, upper = 0.0;
  std::string lower_status, upper_status;
  std::optional<std::pair<double, double>> inner;
};

// Intervals, coverage of the truth, mean width and (when every parameter is bounded) the model at the interval
// centres with its discrete quantities: the part of the report both set-membership methods share.
void ReportIntervals(const Scenario& s, const SetMembershipClass& cls, const std::vector<ReportedInterval>& intervals,
                     const std::vector<std::pair<double, double>>& box, bool all_guaranteed, double tolerance,
                     const Record& val, json* out) {
  json ivs = json::array();
  int covered = 0;
  double width_sum = 0.0;
  std::vector<double> mid = cls.theta;  // filled for every computed parameter
  for (const auto& iv : intervals) {
    const std::size_t k = std::find(cls.names.begin(), cls.names.end(), iv.name) - cls.names.begin();
    const double t = cls.theta[k];
    const double tol = tolerance * (1.0 + std::abs(t));
    const bool in = iv.lower - tol <= t && t <= iv.upper + tol;
    covered += in;
    width_sum += iv.upper - iv.lower;
    mid[k] = 0.5 * (iv.lower + iv.upper);
    json j = {{"name", iv.name}, {"lower", iv.lower}, {"upper", iv.upper}, {"lower_status", iv.lower_status},
              {"upper_status", iv.upper_status}, {"width", iv.upper - iv.lower}, {"truth", t}, {"covered", in},
              {"box", {box[k].first, box[k].second}}};
    if (iv.inner) j["inner"] = {iv.inner->first, iv.inner->second};
    ivs.push_back(j);
  }
  (*out)["intervals"] = ivs;
  (*out)["coverage"] = {{"covered", covered}, {"total", intervals.size()}, {"all_guaranteed", all_guaranteed}};
  (*out)["mean_width"] = intervals.empty() ? 0.0 : width_sum / intervals.size();
  (*out)["status"] = ToString(MethodStatus::kOk);
  if (intervals.size() == cls.names.size()) {
    // Point estimate: the centre of the interval box (each parameter's midpoint).
    (*out)["point_estimate"] = {{"names", cls.names}, {"values", mid}, {"kind", "midpoints of the intervals"}};
    DiscreteQuantities(s, s.plant, PlantFromTheta(cls, mid), val, out);
  } else {
    const std::string why = "only some intervals were computed (setmembership.parameters): no point estimate";
    (*out)["not_available"] = {{"static_rms_pct", why}, {"static_max_pct", why}, {"freq_max_error", why},
                               {"freq_rms_error", why}, {"fit_pct", why}};
  }
}

json RunSetMembership(const Scenario& s, const SetMembershipClass& cls, const OuterSetRun& run, double bound,
                      const Record& val) {
  json out = {{"applicable", true}};
  const auto& summary = run.summary;
  out["noise_bound"] = bound;
  out["samples"] = run.data.u.size();
  out["orthants"] = {{"total", summary.orthants_total}, {"empty", summary.orthants_empty},
                     {"solved", summary.orthants_solved}, {"failed", summary.orthants_failed}};
  out["sdp_solves"] = summary.sdp_solves;
  std::vector<ReportedInterval> ivs;
  for (const auto& iv : summary.intervals)
    ivs.push_back({iv.name, iv.lower.value, iv.upper.value, dss::ToString(iv.lower.status),
                   dss::ToString(iv.upper.status), {}});
  ReportIntervals(s, cls, ivs, run.box, summary.all_guaranteed(), 1e-6 /* SDP solver accuracy */, val, &out);
  return out;
}

// The exact set D on the same record: stage 1 is the D^ss(n) run above, stage 2 bounds D inside its box
// (exact/exact_bounds.hpp), with an inner hull so every interval shows its tightness.
json RunExactSet(const Scenario& s, const SetMembershipClass& cls, const OuterSetRun& run, double bound,
                 const Record& val) {
  json out = {{"applicable", true}};
  out["noise_bound"] = bound;
  out["samples"] = run.data.u.size();
  out["stage1_seconds"] = run.summary.wall_seconds;  // the D^ss(n) run, shared with `setmembership`
  if (run.summary.invalidated()) {
    out["status"] = ToString(MethodStatus::kFailed);
    out["message"] = "D^ss(n) is empty (certified), and D with it: no model of the class explains the record";
    return out;
  }
  exact::ExactBoundsOptions o;
  o.executor = std::make_shared<sdp::InProcessExecutor>();
  o.parameters = s.setmembership.parameters;
  const auto summary =
      exact::ComputeExactBounds(o, cls.structure, run.data, exact::StartBoxFromOuter(run.summary, run.set));
  out["assumption"] = summary.assumption.to_json();
  out["invalidated"] = summary.invalidated;
  out["stage2"] = summary.to_json().at("stage2");
  if (summary.invalidated) {
    out["status"] = ToString(MethodStatus::kFailed);
    out["message"] = "the exact set is empty (certified): no model of the class explains the record";
    return out;
  }
  std::vector<ReportedInterval> ivs;
  bool all_guaranteed = true;
  for (const auto& iv : summary.intervals) {
    if (!o.parameters.empty() &&
        std::find(o.parameters.begin(), o.parameters.end(), iv.name) == o.parameters.end())
      continue;
    ivs.push_back({iv.name, iv.lower.value, iv.upper.value, exact::ToString(iv.lower.status),
                   exact::ToString(iv.upper.status), iv.inner});
    all_guaranteed = all_guaranteed && iv.lower.status != exact::EndpointStatus::kConservative &&
                     iv.upper.status != exact::EndpointStatus::kConservative;
  }
  ReportIntervals(s, cls, ivs, run.box, all_guaranteed, 0.0 /* certified bounds: no tolerance */, val, &out);
  return out;
}

// Esmaeilani's estimate in paper 001's parametrisation: a exactly (same order); gamma, alpha and b through a
// least-squares projection of the ordered pairs onto the power basis (with a free constant, which is a
// normalisation), as the pairs are piecewise linear and no polynomial represents them exactly.
json MapEsmaeilaniToSetMembership(const esmaeilani::EsmaeilaniModel& m, const HwModel& hm,
                                  const SetMembershipClass& cls, double lo, double hi) {
  const auto layout = dss::MakeLayout(cls.structure);
  const int din = static_cast<int>(cls.structure.input_basis.size());
  const int dout = static_cast<int>(cls.structure.output_basis.size());
  const auto uu = Linspace(lo, hi, 201);
  std::vector<double> fu;
  for (double v : uu) fu.push_back(m.F(v));
  const auto cf = brouri::PolyFit(uu, fu, din);  // ascending, c[0] constant
  const auto yy = Linspace(m.y_grid.front(), m.y_grid.back(), 201);
  std::vector<double> gy;
  for (double v : yy) gy.push_back(m.Ginv(v));
  const auto cg = brouri::PolyFit(yy, gy, dout);
  auto rel_residual = [](const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& c) {
    double r = 0.0, n = 0.0;
    const double mean = std::accumulate(y.begin(), y.end(), 0.0) / y.size();
    for (std::size_t i = 0; i < x.size(); ++i) {
      r += std::pow(brouri::PolyEval(c, x[i]) - y[i], 2);
      n += std::pow(y[i] - mean, 2);
    }
    return std::sqrt(r / std::max(n, 1e-300));
  };
  const double rf = rel_residual(uu, fu, cf), rg = rel_residual(yy, gy, cg);
  json out = json::array();
  auto add = [&](const std::string& name, double v, const std::string& mapping, double residual = 0.0) {
    out.push_back({{"name", name}, {"value", v}, {"mapping", mapping}, {"projection_residual", residual}});
  };
  const std::string pf = "projected: LS fit of f's pairs onto the power basis";
  const std::string pg = "projected: LS fit of g^-1's pairs onto the power basis";
  for (int k = 0; k < layout.num_gamma; ++k) add(cls.names[layout.gamma_begin + k], cf[k + 2] / cf[1], pf, rf);
  for (int k = 0; k < layout.num_alpha; ++k) add(cls.names[layout.alpha_begin + k], cg[k + 2] / cg[1], pg, rg);
  const bool same_order = static_cast<int>(hm.linear.a.size()) == cls.structure.na;
  for (int i = 0; i < cls.structure.na; ++i)
    add(cls.names[layout.a_begin + i], i < static_cast<int>(hm.linear.a.size()) ? hm.linear.a[i] : 0.0,
        same_order ? "exact (denominator is normalisation-free)" : "orders differ: not comparable");
  std::vector<double> lag(hm.linear.delay + hm.linear.b.size(), 0.0);
  for (std::size_t j = 0; j < hm.linear.b.size(); ++j) lag[hm.linear.delay + j] = hm.linear.b[j];
  const int j0 = cls.structure.strictly_proper ? 1 : 0;
  for (int j = j0; j <= cls.structure.nb; ++j)
    add(cls.names[layout.b_begin + j - j0], j < static_cast<int>(lag.size()) ? lag[j] * cf[1] / cg[1] : 0.0,
        "rescaled by the projected linear coefficients of f and g^-1", std::max(rf, rg));
  return out;
}

json RunEsmaeilani(const Scenario& s, const std::vector<Record>& recs, const Record& val) {
  json out = {{"applicable", true}};
  std::vector<esmaeilani::Segment> segs;
  for (std::size_t k = 0; k < recs.size(); ++k) segs.push_back({recs[k].u, recs[k].y, fmt::format("record{}", k)});
  esmaeilani::Options opt;
  esmaeilani::Constraints cons;
  const auto& es = s.esmaeilani;
  opt.grid_f = es.grid_f;
  opt.grid_g = es.grid_g;
  opt.max_iterations = es.max_iterations;
  if (s.kind == PlantKind::kValve) {
    cons = esmaeilani::ValveCase().KnownInformation();
    opt.order = 3;
  } else {
    const auto& lin = s.plant.model.linear;
    const int lags = lin.delay + static_cast<int>(lin.b.size()) - 1;
    opt.order = std::max<int>(lin.a.size(), std::max(1, lags));
    cons.fix_d_zero = lin.delay > 0 || lin.b[0] == 0.0;
    // Normalisation only (no knowledge of the truth): f(0) = 0 (its offset is absorbed by m_e), f(u*) = u*
    // (its scale by b), g^-1 = identity at the quartiles of y (affine normalisation), g^-1 nondecreasing
    // (after that normalisation, any invertible output map is).
    double ustar = s.input_lo + 0.75 * (s.input_hi - s.input_lo);
    if (std::abs(ustar) < 1e-9) ustar = s.input_hi;
    cons.f.points = {{0.0, 0.0, 0.0}, {ustar, ustar, ustar}};
    std::vector<double> ys;
    for (const auto& r : recs) ys.insert(ys.end(), r.y.begin(), r.y.end());
    std::sort(ys.begin(), ys.end());
    const double q1 = ys[ys.size() / 4], q3 = ys[3 * ys.size() / 4];
    cons.g_inverse.points = {{q1, q1, q1}, {q3, q3, q3}};
    cons.g_inverse.slopes.push_back({-1e20, 1e20, 0.0, 1e20});
  }
  out["order"] = opt.order;
  out["constraints"] = cons.ToJson();
  esmaeilani::Summary sum;
  const auto m = esmaeilani::Estimate(opt, segs, cons, &sum);
  out["iterations"] = sum.iterations;
  out["final_cost"] = sum.final_cost;
  out["message"] = sum.message;
  if (!sum.ok()) {
    out["status"] = ToString(MethodStatus::kFailed);
    return out;
  }
  out["status"] = ToString(MethodStatus::kOk);
  Plant est;
  est.model = m.ToHwModel(true);
  out["model"] = est.model.to_json();
  DiscreteQuantities(s, s.plant, est, val, &out);
  const auto cls = SetMembershipTruth(s.plant);
  if (cls.ok && MethodApplies(s, "setmembership").applies)
    out["setmembership_parametrisation"] = MapEsmaeilaniToSetMembership(m, est.model, cls, s.input_lo, s.input_hi);
  return out;
}

double WrapPi(double x) {
  x = std::fmod(x + kPi, 2 * kPi);
  if (x < 0) x += 2 * kPi;
  return x - kPi;
}

json RunBrouri(const Scenario& s, std::uint64_t seed) {
  json out = {{"applicable", true}};
  auto cfg = brouri::WorkflowConfig::Paper();
  cfg.periods = s.brouri.periods;
  cfg.samples_per_period = s.brouri.samples_per_period;
  if (!s.brouri.omegas.empty()) cfg.omegas = s.brouri.omegas;
  const auto r = brouri::RunWorkflow(s.backlash, cfg, seed);
  out["message"] = r.nonlinear_summary.message;
  if (!r.nonlinear_summary.ok) {
    out["status"] = ToString(MethodStatus::kFailed);
    return out;
  }
  for (const auto& ps : r.point_summaries)
    if (!ps.ok) {
      out["status"] = ToString(MethodStatus::kFailed);
      out["message"] = "frequency stage: " + ps.message;
      return out;
    }
  out["status"] = ToString(MethodStatus::kOk);
  // Static: the two steady-state borders of the normalised model (same input-output behaviour as the plant).
  const auto truth = s.backlash.Normalised();
  const auto tl = brouri::LinesOf(truth.kind, truth.backlash);
  const auto& el = r.nonlinear.lines;
  // Each border is compared over the levels the experiment applies along it (beyond that it is extrapolation).
  const auto range = [](const std::vector<double>& v) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return Linspace(*lo, *hi, 101);
  };
  const auto u_up = range(cfg.steps.levels_up), u_down = range(cfg.steps.levels_down);
  std::vector<double> yt, ye, up, down;
  for (double v : u_up) {
    yt.push_back(brouri::PolyEval(truth.h, tl.slope_up * (v - tl.root_up)));
    ye.push_back(brouri::PolyEval(r.nonlinear.h, el.slope_up * (v - el.root_up)));
    up.push_back(ye.back());
  }
  for (double v : u_down) {
    yt.push_back(brouri::PolyEval(truth.h, tl.slope_down * (v - tl.root_down)));
    ye.push_back(brouri::PolyEval(r.nonlinear.h, el.slope_down * (v - el.root_down)));
    down.push_back(ye.back());
  }
  const auto [ylo, yhi] = std::minmax_element(yt.begin(), yt.end());
  double ss = 0.0, mx = 0.0;
  for (std::size_t i = 0; i < yt.size(); ++i) {
    ss += (ye[i] - yt[i]) * (ye[i] - yt[i]);
    mx = std::max(mx, std::abs(ye[i] - yt[i]));
  }
  json& q = out["quantities"];
  q["static_rms_pct"] = 100.0 * std::sqrt(ss / yt.size()) / std::max(*yhi - *ylo, 1e-300);
  q["static_max_pct"] = 100.0 * mx / std::max(*yhi - *ylo, 1e-300);
  double gmx = 0.0, gss = 0.0, pmx = 0.0;
  std::vector<double> om, gain, phase;
  for (const auto& p : r.points) {
    const auto G = truth.g.Response(p.omega) / truth.g.StaticGain();
    const double e = p.gain - std::abs(G);
    gmx = std::max(gmx, std::abs(e));
    gss += e * e;
    pmx = std::max(pmx, std::abs(WrapPi(p.phase - (-std::arg(G)))));
    om.push_back(p.omega);
    gain.push_back(p.gain);
    phase.push_back(p.phase);
  }
  q["freq_max_error"] = gmx;
  q["freq_rms_error"] = std::sqrt(gss / std::max<std::size_t>(1, r.points.size()));
  q["phase_max_error_rad"] = pmx;
  out["not_available"]["fit_pct"] =
      "Brouri's method gives G at the tested frequencies only (no parametric G(s)), so there is no model to simulate";
  out["curves"] = {{"static_u_up", u_up}, {"static_up", up}, {"static_u_down", u_down}, {"static_down", down},
                   {"omega", om}, {"gain", gain}, {"phase", phase}};
  out["estimate"] = {{"lines", {{"slope_up", el.slope_up}, {"root_up", el.root_up}, {"slope_down", el.slope_down},
                                {"root_down", el.root_down}}},
                     {"h", r.nonlinear.h}};
  return out;
}

}  // namespace

Record OperatingRecord(const Plant& plant, double lo, double hi, int samples, int hold_min, int hold_max,
                       double bound, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> level(lo, hi), unit(-1.0, 1.0);
  std::uniform_int_distribution<int> hold(hold_min, hold_max);
  Record r;
  while (static_cast<int>(r.u.size()) < samples) {
    const double v = level(rng);
    const int h = hold(rng);
    for (int k = 0; k < h && static_cast<int>(r.u.size()) < samples; ++k) r.u.push_back(v);
  }
  r.w = plant.simulate(r.u);
  if (r.w.size() != r.u.size()) throw InputError("the plant's output map cannot be evaluated on the operating record");
  for (double w : r.w) r.y.push_back(w + bound * unit(rng));
  return r;
}

Record RandomInputRecord(const Plant& plant, double lo, double hi, int samples, double snr_db, double bound,
                         std::uint64_t seed, double* bound_used) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> input(lo, hi), unit(-1.0, 1.0);
  Record r;
  r.u.resize(samples);
  for (auto& v : r.u) v = input(rng);
  r.w = plant.simulate(r.u, 0);  // from rest, as paper 001's example
  if (r.w.size() != r.u.size()) throw InputError("the plant's output map cannot be evaluated on the random-input record");
  if (!(bound > 0)) {
    double pw = 0.0;
    for (double w : r.w) pw += w * w;
    bound = std::sqrt(3.0 * (pw / samples) / std::pow(10.0, snr_db / 10.0));
  }
  for (double w : r.w) r.y.push_back(w + bound * unit(rng));
  if (bound_used) *bound_used = bound;
  return r;
}

Record ValidationRecord(const Scenario& s, std::uint64_t study_seed) {
  if (s.kind == PlantKind::kBacklash) return {};
  const std::uint64_t seed = study_seed * 2654435761ULL + 0x5eed;
  if (s.kind == PlantKind::kValve) {
    Record r;
    r.u = esmaeilani::ValveCase().ClosingOperation(static_cast<unsigned>(seed % 4000000000ULL), s.validation.samples).u;
    r.w = s.plant.simulate(r.u);
    return r;
  }
  auto r = OperatingRecord(s.plant, s.input_lo, s.input_hi, s.validation.samples, s.validation.hold_min,
                           s.validation.hold_max, 0.0, seed);
  r.y = r.w;
  return r;
}

nlohmann::json TruthCurves(const Scenario& s) {
  json c;
  if (s.kind == PlantKind::kBacklash) {
    const auto truth = s.backlash.Normalised();
    const auto tl = brouri::LinesOf(truth.kind, truth.backlash);
    const auto steps = brouri::WorkflowConfig::Paper().steps;
    const auto range = [](const std::vector<double>& v) {
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      return Linspace(*lo, *hi, 101);
    };
    const auto u_up = range(steps.levels_up), u_down = range(steps.levels_down);
    std::vector<double> up, down, om, gain;
    for (double v : u_up) up.push_back(brouri::PolyEval(truth.h, tl.slope_up * (v - tl.root_up)));
    for (double v : u_down) down.push_back(brouri::PolyEval(truth.h, tl.slope_down * (v - tl.root_down)));
    for (int k = 0; k <= 200; ++k) {
      const double w = 0.005 * std::pow(100.0, k / 200.0);
      om.push_back(w);
      gain.push_back(std::abs(truth.g.Response(w) / truth.g.StaticGain()));
    }
    return {{"static_u_up", u_up}, {"static_up", up}, {"static_u_down", u_down}, {"static_down", down},
            {"omega", om}, {"gain", gain}};
  }
  const auto u = Linspace(s.input_lo, s.input_hi, 101);
  std::vector<double> y, g;
  for (double v : u) y.push_back(s.plant.steady_state(v).value_or(std::nan("")));
  const auto w = OmegaGrid();
  for (double om : w) g.push_back(s.plant.normalised_gain(om));
  return {{"static_u", u}, {"static_y", y}, {"omega", w}, {"gain", g}};
}

nlohmann::json RunOne(const Scenario& s, const std::vector<std::string>& methods, int run, std::uint64_t study_seed) {
  const std::uint64_t seed = study_seed + static_cast<std::uint64_t>(run);
  json out = {{"run", run}, {"seed", seed}, {"scenario", s.name}, {"methods", json::object()}};
  const Record val = ValidationRecord(s, study_seed);
  // The noise level: set once per run from the set-membership record, then used by every method's record.
  Record smrec;
  double bound = 0.0;
  if (s.kind == PlantKind::kDiscreteHw) {
    smrec = RandomInputRecord(s.plant, s.input_lo, s.input_hi, s.setmembership.samples, s.snr_db, s.noise_bound,
                              seed, &bound);
    out["noise_bound"] = bound;
  }
  // The D^ss(n) run, once per run however many set-membership methods report from it.
  std::optional<OuterSetRun> outer;
  auto outer_set = [&]() -> const OuterSetRun& {
    if (!outer) outer.emplace(RunOuterSet(s, SetMembershipTruth(s.plant), smrec, bound));
    return *outer;
  };
  for (const auto& method : methods) {
    const auto app = MethodApplies(s, method);
    json m;
    if (!app.applies) {
      m = {{"applicable", false}, {"reason", app.reason}};
      out["methods"][method] = m;
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    try {
      if (method == "setmembership") {
        m = RunSetMembership(s, SetMembershipTruth(s.plant), outer_set(), bound, val);
      } else if (method == "exact") {
        m = RunExactSet(s, SetMembershipTruth(s.plant), outer_set(), bound, val);
      } else if (method == "esmaeilani") {
        std::vector<Record> recs;
        for (int k = 0; k < s.esmaeilani.segments; ++k) {
          const std::uint64_t sk = seed * 1000003ULL + 17 + k;
          if (s.kind == PlantKind::kValve) {
            Record r;
            const auto seg = esmaeilani::ValveCase().ClosingOperation(static_cast<unsigned>(sk % 4000000000ULL),
                                                                       s.esmaeilani.samples);
            r.u = seg.u;
            r.y = seg.y;
            recs.push_back(r);
          } else {
            recs.push_back(OperatingRecord(s.plant, s.input_lo, s.input_hi, s.esmaeilani.samples,
                                           s.esmaeilani.hold_min, s.esmaeilani.hold_max, bound, sk));
          }
        }
        m = RunEsmaeilani(s, recs, val);
      } else if (method == "brouri") {
        m = RunBrouri(s, seed);
      }
    } catch (const std::exception& e) {
      // A method that fails is reported, never dropped.
      m = {{"applicable", true}, {"status", ToString(MethodStatus::kFailed)}, {"message", e.what()}};
    }
    m["experiment"] = app.experiment;
    m["seconds"] = Seconds(t0);
    out["methods"][method] = m;
  }
  // Point estimates mapped into the set-membership parametrisation against its intervals.
  if (out["methods"].contains("setmembership") && MethodStatusOf(out["methods"]["setmembership"]) == MethodStatus::kOk) {
    const auto& ivs = out["methods"]["setmembership"]["intervals"];
    for (auto& [name, m] : out["methods"].items()) {
      if (!m.contains("setmembership_parametrisation")) continue;
      json checks = json::array();
      int inside = 0, total = 0;
      for (const auto& p : m["setmembership_parametrisation"]) {
        for (const auto& iv : ivs)
          if (iv["name"] == p["name"]) {
            const double v = p["value"], lo = iv["lower"], hi = iv["upper"];
            const bool in = lo <= v && v <= hi;
            inside += in;
            ++total;
            checks.push_back({{"name", p["name"]}, {"value", v}, {"lower", lo}, {"upper", hi}, {"inside", in},
                              {"mapping", p["mapping"]}, {"projection_residual", p["projection_residual"]}});
          }
      }
      m["inside_setmembership_intervals"] = {{"inside", inside}, {"total", total}, {"parameters", checks}};
    }
  }
  return out;
}

}  // namespace hw::compare
