#pragma once
// One small interface for interchangeable SDP backends (CSDP, SDPA, DSDP), in the manner of Ceres:
// options are a plain struct with defaults and IsValid(), the outcome is a summary with an explicit
// status and message, and each backend's own details travel beside the common result.
#include <functional>
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
  // A solve that stops short of gap_tolerance (SDPA "pdFEAS", CSDP "partial success") is still called
  // optimal when both sides are feasible within this and the relative gap is below it: the reported
  // bound comes from the feasible dual side, so the gap only costs tightness, not validity.
  double acceptable_gap = 1e-6;
  bool verbose = false;                 // let the backend print its iteration log
  bool keep_dual_matrix = true;         // return X (needed for verification and for flatness)
  // An infeasibility claim is accepted only with a certificate: X >= 0 with
  // sum_i |F_i . X| <= infeasibility_tolerance * F_0 . X (then sum y_i F_i - F_0 >= 0 is impossible for
  // |y_i| <= 1 / infeasibility_tolerance). Backends' own phase labels are not trusted alone.
  double infeasibility_tolerance = 1e-4;
  // SDPA only: a solve that ends undecided with SDPA's stable parameter set is repeated with its default set
  // (small POPs that stopped at pdFEAS/dFEAS finish that way). Callers with their own fallback chain turn it
  // off: on large ill-conditioned LMIs the second attempt mostly fails too and doubles the cost.
  bool retry_with_default_parameters = true;
  // A warm start where the backend takes one (DSDP: its initial y; CSDP and SDPA ignore it). Empty = none;
  // otherwise one value per variable of the problem as posed.
  std::vector<double> initial_y;
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
  double solve_seconds = 0.0;  // the solver call alone; waiting for the solver lock is details["lock_wait_seconds"]
  double relative_gap = 0.0;
  double primal_infeasibility = 0.0;  // of F_i . X = c_i
  double dual_infeasibility = 0.0;    // of the LMI at y
  nlohmann::json details;             // the backend's own report (phase values, raw codes)

  // True only when status is kOptimal: a bound read from any other outcome is never reported as valid.
  bool usable() const { return status == SdpStatus::kOptimal; }
  // The solve settled the problem (optimal, or certified infeasible/unbounded); anything else is worth a retry.
  bool decided() const {
    return status == SdpStatus::kOptimal || status == SdpStatus::kInfeasible || status == SdpStatus::kUnbounded;
  }
};

// Solve() may be called from several threads at once (each call owns its data), but all three libraries keep
// process-wide state, so each backend serialises its solver calls with a process-wide mutex (see
// csdp_backend.cpp / sdpa_backend.cpp / dsdp_backend.cpp and docs/sdp.md): concurrency pays off for the work
// around solves.
class SdpSolver {
 public:
  virtual ~SdpSolver() = default;
  virtual std::string name() const = 0;
  virtual SdpSummary Solve(const SdpOptions& options, const LmiProblem& problem) = 0;
};

// F . X for one matrix of the problem (upper-triangular entries; off-diagonal ones count twice) and a block X.
double InnerProduct(const std::vector<Entry>& F, const std::vector<Eigen::MatrixXd>& X);
// sum_i |F_i . X| / F_0 . X for a candidate certificate X (infinity when X is not PSD or F_0 . X <= 0).
double InfeasibilityResidual(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X);
// Turns a backend's infeasibility claim into kInfeasible (certificate checked) or kNumericalTrouble.
void ConfirmInfeasibility(const SdpOptions& options, const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                          SdpSummary* summary);

// For a candidate ray d (normalised inside): max(0, -lambda_min(sum d_i F_i)) / (-c^T d); infinity unless
// c^T d < 0. Small means d is (nearly) a direction along which c^T y decreases without leaving the LMI.
double UnboundednessResidual(const LmiProblem& problem, const std::vector<double>& d);
// Settles a backend's claim of infeasibility or unboundedness by the certificates, never by the label:
// X certifies infeasibility -> kInfeasible; else y is a ray -> kUnbounded; else kNumericalTrouble.
// kUnbounded does not separately prove that the LMI is feasible (either way no bound is usable).
void ResolveInfeasibilityClaim(const SdpOptions& options, const LmiProblem& problem, SdpSummary* summary);

// Promotes kInaccurate to kOptimal when the gap and infeasibilities are within options.acceptable_gap.
void AcceptNearOptimal(const SdpOptions& options, SdpSummary* summary);

// Backend plumbing shared by every backend. CSDP and SDPA choke on a variable whose F_i is zero (CSDP even
// calls exit()), and duplicate entries mean different things to different solvers, so every backend solves
// the canonical reduced problem: duplicates summed, zeros dropped, variables with F_i = 0 removed.
// SolveCanonical() does that, solves with `solve` (given the options as they apply to the reduced problem:
// initial_y restricted to the kept variables), and maps y back (removed variables get y_i = 0; a removed
// variable with c_i != 0 makes a feasible problem unbounded). A problem left without variables is decided
// directly: F(y) = -F_0 >= 0 or not (an eigenvector of -F_0 certifies infeasibility).
using CanonicalSolve = std::function<SdpSummary(const SdpOptions& reduced_options, const LmiProblem& reduced)>;
SdpSummary SolveCanonical(const SdpOptions& options, const LmiProblem& problem, const CanonicalSolve& solve);
// SolveCanonical, then the steps every backend shares: name the solver and drop X, Z unless kept.
SdpSummary SolveAsBackend(const std::string& name, const SdpOptions& options, const LmiProblem& problem,
                          const CanonicalSolve& solve);
// Relative duality gap as both backends report it: |p - d| / max(1, (|p| + |d|) / 2).
double RelativeGap(double primal, double dual);

// "csdp", "sdpa" or "dsdp"; throws std::invalid_argument for other names.
std::unique_ptr<SdpSolver> MakeSolver(const std::string& name);
std::vector<std::string> AvailableSolvers();
// True for a name of AvailableSolvers(); otherwise false with "solver 'NAME' unknown; expected ..." in *error
// (the message of every caller: the engine, the CLI and the Python module).
bool ValidSolverName(const std::string& name, std::string* error);

// One BLAS thread for the whole process: jobs run in parallel in our own pool, never inside BLAS, so
// results do not depend on the core count. Called by every SDP solve and every local (Ipopt) solve.
void UseSingleThreadedBlas();

}  // namespace hw::sdp
