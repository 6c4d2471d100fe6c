#pragma once
// One small interface for interchangeable SDP backends (CSDP, SDPA), in the manner of Ceres:
// options are a plain struct with defaults and IsValid(), the outcome is a summary with an explicit
// status and message, and each backend's own details travel beside the common result.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "sdp/lmi_problem.hpp"

namespace hw::sdp {

struct SdpOptions {
  double gap_tolerance = 1e-7;         // relative duality gap to call a solve optimal
  double feasibility_tolerance = 1e-7;  // relative primal/dual infeasibility
  int max_iterations = 200;
  bool verbose = false;                 // let the backend print its iteration log
  bool keep_dual_matrix = true;         // return X (needed for verification and for flatness)
  bool IsValid(std::string* error) const;
};

enum class SdpStatus {
  kOptimal,           // both sides feasible, gap within tolerance: lower_bound is usable
  kInfeasible,        // the LMI F(y) >= 0 has no solution (certificate in X); min is +infinity
  kUnbounded,         // c^T y unbounded below on the LMI
  kInaccurate,        // stopped with a partial solution that misses the tolerances
  kIterationLimit,    // ran out of iterations
  kNumericalTrouble,  // the backend gave up (Schur complement not PD, line search failure, ...)
  kInvalidProblem,    // rejected before the solve
};
std::string ToString(SdpStatus s);

struct SdpSummary {
  SdpStatus status = SdpStatus::kInvalidProblem;
  std::string message;
  std::string solver;
  // Values of the problem as posed (min c^T y + offset):
  double primal_value = 0.0;  // c^T y + offset at the returned y (an upper estimate of the optimum)
  double lower_bound = 0.0;   // F_0 . X + offset at the returned X (a lower estimate; see lmi_problem.hpp)
  std::vector<double> y;                 // free variables, size m
  std::vector<Eigen::MatrixXd> X;        // LMI multiplier, block by block (diagonal blocks as n x n)
  std::vector<Eigen::MatrixXd> Z;        // slack F(y), block by block
  int iterations = 0;
  double setup_seconds = 0.0;
  double solve_seconds = 0.0;
  double relative_gap = 0.0;
  double primal_infeasibility = 0.0;  // of F_i . X = c_i
  double dual_infeasibility = 0.0;    // of the LMI at y
  nlohmann::json details;             // the backend's own report (phase values, raw codes)

  // True only when status is kOptimal: a bound read from any other outcome is never reported as valid.
  bool usable() const { return status == SdpStatus::kOptimal; }
};

class SdpSolver {
 public:
  virtual ~SdpSolver() = default;
  virtual std::string name() const = 0;
  virtual SdpSummary Solve(const SdpOptions& options, const LmiProblem& problem) = 0;
};

// "csdp" or "sdpa"; throws std::invalid_argument for other names.
std::unique_ptr<SdpSolver> MakeSolver(const std::string& name);
std::vector<std::string> AvailableSolvers();

}  // namespace hw::sdp
