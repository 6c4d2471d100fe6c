#pragma once
// What the branch and bound asks of one box: is it empty (proven), and how far does a parameter (or a ratio
// of input-side parameters) reach inside it (proven). Each answer comes from lifted LPs (exact/lifted_lp.hpp)
// solved in floating point and certified by exact/safe_bound.hpp; a box whose LPs fail or do not certify is
// kept with the bound it inherited, never dropped.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/lifted_lp.hpp"
#include "exact/lp_solver.hpp"

namespace hw::exact {

// How a box was proven empty: the rigorous lower bound of the largest equation residual over the samples
// of `window` is positive.
struct PruneCertificate {
  Window window;
  double residual_lower_bound = 0.0;  // > 0
  nlohmann::json to_json() const;
  static PruneCertificate from_json(const nlohmann::json& j);
};

// A linear objective of the branch and bound: a parameter (index in the layout), or gamma_k through the ratio
// beta_jk / b_j (Dinkelbach steps; needs b_j of one sign over the box).
struct Objective {
  int parameter = 0;
  bool maximise = false;
};

struct BoxEvaluationOptions {
  // Cheap windows tried before the whole record (each a valid relaxation: fewer equations): samples per
  // window; 0 = whole record only.
  int cheap_window = 100;
  int cheap_windows = 2;  // how many, spread over the record
  LpSolveOptions lp;
  bool IsValid(std::string* error) const;
};

enum class BoxVerdict { kPruned, kKept };

// How a gamma_k is bounded once b_j of one sign exist: gamma_k = beta_jk / b_j for each such j, and as well
// gamma_k = (sum_j s_j beta_jk) / (sum_j s_j b_j) with s_j the sign of b_j. The relaxation leaves the beta_jk of
// different j free of each other, so the ratios bound gamma_k differently.
enum class GammaRatio {
  kLargest,  // beta_jk / b_j with the b_j farthest from zero
  kRotate,   // each b_j of one sign in turn (by the box's depth); a search keeps the tightest
  kPooled,   // all b_j of one sign at once: the LP cannot push each ratio to its own extreme
};
std::string ToString(GammaRatio ratio);
bool ParseGammaRatio(const std::string& text, GammaRatio* ratio);

struct BoxEvaluation {
  BoxVerdict verdict = BoxVerdict::kKept;
  std::optional<PruneCertificate> certificate;  // with kPruned
  std::optional<double> bound;   // rigorous bound of the objective over the box (asked for and obtained)
  double lp_value = 0.0;         // the LP's floating-point optimum of the objective (for `correction`)
  std::vector<double> point;     // parameter values of the last LP solution (a start for local searches)
  int lps = 0;
  int lp_failures = 0;           // LPs that ended without an optimal solution
  double seconds = 0.0;
  LpBasis basis;                 // of the whole-record LP, for a child box
};

// The emptiness test alone: cheap windows, then the whole record.
BoxEvaluation TestBoxEmpty(const LiftedData& data, const ParamBox& box, const BoxEvaluationOptions& options,
                           LpSolver& solver, const LpBasis& warm = {});
// The objective's rigorous bound over the box (min: a lower bound; max: an upper bound). An infeasible LP
// leads to the emptiness test on the whole record.
// A gamma_k is bounded as a ratio once some b_j has a sign over the box: `ratio` says which ratio, `turn` which
// b_j (with GammaRatio::kRotate: the farthest from zero first, cyclically). `ratio_start`, when inside the box,
// is where the ratio's Dinkelbach steps start (a parent box's LP ratio: near the answer, fewer LPs); else the
// middle of the box.
BoxEvaluation BoundObjective(const LiftedData& data, const ParamBox& box, const Objective& objective,
                             const BoxEvaluationOptions& options, LpSolver& solver, const LpBasis& warm = {},
                             GammaRatio ratio = GammaRatio::kLargest, int turn = 0,
                             std::optional<double> ratio_start = std::nullopt);

// The whole record as a window.
Window WholeRecord(const LiftedData& data);
// The cheap windows of a record: `count` windows of `length` samples spread evenly.
std::vector<Window> CheapWindows(const LiftedData& data, int length, int count);

}  // namespace hw::exact
