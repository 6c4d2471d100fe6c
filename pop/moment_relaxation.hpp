#pragma once
// Lasserre's moment relaxation of order delta for
//     min (or max) f(x)  s.t.  g_i(x) >= 0,  h_j(x) = 0,  optional box lo <= x <= hi,
// as a solver-neutral LMI problem in the free moment variables y_alpha, 0 < |alpha| <= 2 delta
// (y_0 = 1 is a constant). Blocks: the moment matrix M_delta(y), one localizing matrix
// M_{delta - d_i}(g_i y) per inequality (d_i = ceil(deg g_i / 2)); localizing matrices of size 1
// are gathered into one diagonal (LP) block. Equalities L_y(h_j x^beta) = 0, |beta| <= 2 delta - deg h_j,
// are eliminated exactly (reduced row echelon form), never split into two inequalities.
//
// Guarantee: for min, the SDP's dual value (F_0 . X side) is a lower bound on the POP's minimum,
// whatever the solver's primal accuracy; it is reported only when the solve is optimal.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/polynomial.hpp"
#include "sdp/lmi_problem.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::pop {

struct PolyProblem {
  int num_vars = 0;
  std::vector<std::string> names;  // optional; x1..xn when empty
  Polynomial objective;
  bool maximize = false;
  std::vector<Polynomial> inequalities;  // g_i(x) >= 0
  std::vector<Polynomial> equalities;    // h_j(x) = 0
  std::vector<std::pair<double, double>> box;  // optional per-variable [lo, hi] (all or none)

  bool IsValid(std::string* error) const;
  int max_degree() const;
  int minimal_order() const;  // smallest delta for which the relaxation is defined
};

// Fast lookup of monomial indices in the graded basis of degree <= 2 delta.
class MomentIndex {
 public:
  MomentIndex(int num_vars, int max_degree);
  const MonomialBasis& basis() const { return basis_; }
  long index_of(const Exponents& e) const { return basis_.index_of(e); }
  // Index of monomial(i) * monomial(j) for basis indices i, j, or -1 if beyond the max degree.
  long product(long i, long j) const;

 private:
  MonomialBasis basis_;
  std::vector<uint64_t> keys_;
  std::unordered_map<uint64_t, long> by_key_;
  bool packed_ = false;
};

struct RelaxationOptions {
  int order = 0;                       // delta; 0 = minimal order
  double rank_tolerance = 1e-4;        // relative singular-value threshold for ranks (flatness)
  double extraction_tolerance = 1e-4;  // feasibility/objective tolerance to accept extracted minimizers
  sdp::SdpOptions sdp;
  bool IsValid(std::string* error) const;
};

// The LMI of one relaxation, with the bookkeeping to map solver variables back to moments.
class MomentRelaxation {
 public:
  MomentRelaxation(const PolyProblem& problem, int order);
  // Mixed orders (as in the bounded-degree hierarchy): inequality i gets the localizing matrix of order
  // min(localizing_orders[i], order - ceil(deg g_i / 2)); -1 = full order, 0 = the scalar L_y(g_i) >= 0. Any
  // choice relaxes the full order-delta relaxation, so its bound stays valid (and is never tighter).
  MomentRelaxation(const PolyProblem& problem, int order, const std::vector<int>& localizing_orders);

  int order() const { return order_; }
  const sdp::LmiProblem& lmi() const { return lmi_; }
  const MomentIndex& index() const { return index_; }
  // Full moment vector (y_0 = 1 first) from the solver's free variables.
  std::vector<double> moments(const std::vector<double>& solver_y) const;
  // Moment matrix M_k(y) for k <= order.
  Eigen::MatrixXd moment_matrix(const std::vector<double>& moments, int k) const;
  double objective_sign() const { return sign_; }  // +1 for min, -1 for max (the LMI always minimises)
  // Localizing matrix M_k(g y), k = order - ceil(deg g / 2) capped at max_order (-1: no cap), at a full moment
  // vector (for checking constraints that were left out of the LMI).
  Eigen::MatrixXd localizing_matrix(const Polynomial& g, const std::vector<double>& moments, int max_order = -1) const;
  // The full localizing order of g in this relaxation: order - ceil(deg g / 2).
  int full_localizing_order(const Polynomial& g) const;
  // The LMI block of each of the problem's inequalities (box constraints after them); -1 for the scalar ones,
  // which share the diagonal block.
  const std::vector<int>& block_of_inequality() const { return block_of_inequality_; }

 private:
  int order_;
  std::vector<int> block_of_inequality_;
  double sign_ = 1.0;
  MomentIndex index_;
  sdp::LmiProblem lmi_;
  // y_full = base + T z for eliminated equalities (identity when there are none).
  std::vector<double> base_;
  std::vector<std::vector<std::pair<int, double>>> map_;  // per full moment (excluding y0): (z index, coef)
};

enum class RelaxationStatus { kSolved, kInfeasible, kUnbounded, kSolverFailed, kInvalid };
std::string ToString(RelaxationStatus s);

struct RelaxationResult {
  RelaxationStatus status = RelaxationStatus::kInvalid;
  std::string message;
  int order = 0;
  // Valid bound on the POP's optimum (lower for min, upper for max); meaningful when status == kSolved.
  double bound = 0.0;
  double primal_value = 0.0;  // the relaxation's primal objective at the returned moments
  std::vector<double> first_moments;
  int rank = -1;              // numerical rank of the moment matrix at the flat order found
  bool flat = false;          // rank M_s == rank M_{s-d}: the bound is the global optimum
  std::vector<std::vector<double>> minimizers;  // extracted when flat
  sdp::SdpSummary sdp;        // the backend's outcome and details
  std::size_t num_moments = 0;
  std::size_t num_blocks = 0;
};

RelaxationResult SolveRelaxation(const RelaxationOptions& options, const PolyProblem& problem,
                                 sdp::SdpSolver& solver);

// Henrion–Lasserre extraction from a flat moment matrix M (rows/cols = basis monomials of degree <= s).
// Returns the atoms, or an empty vector when the matrix is not flat enough to extract from.
std::vector<std::vector<double>> ExtractMinimizers(const Eigen::MatrixXd& moment_matrix, const MonomialBasis& basis,
                                                   int s, double rank_tolerance);

}  // namespace hw::pop
