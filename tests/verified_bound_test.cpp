// Verified SDP bounds (sdp/verified_bound.hpp): rigorous eigenvalue bounds, verified lower bounds below known
// optima and close to the floating-point ones, perturbed multipliers (looser, still valid), ill-conditioned
// relaxations (unverified or correct, never wrongly verified), infeasibility certificates, and the verification
// status on every set-membership endpoint.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/set_membership.hpp"
#include "pop/constraint_generation.hpp"
#include "pop/moment_lp.hpp"
#include "sdp/verified_bound.hpp"

namespace hw {
namespace {

using pop::MomentRelaxation;
using pop::PolyProblem;

Eigen::MatrixXd RandomOrthogonal(int n, std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = N(rng);
  return Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ();
}

TEST(VerifiedBound, MinEigenvalueLowerBoundIsBelowAndClose) {
  std::mt19937 rng(7);
  for (int n : {1, 5, 40}) {
    for (double lmin : {-1e-3, 0.0, 1e-9, 2.0}) {
      Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(n, lmin, lmin + 10.0);
      const Eigen::MatrixXd Q = RandomOrthogonal(n, rng);
      const Eigen::MatrixXd A = Q * d.asDiagonal() * Q.transpose();
      // The exact lambda_min of the double matrix A differs from lmin by rounding in forming A (~n eps ||A||).
      const double exact = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues()(0);
      const double lb = sdp::MinEigenvalueLowerBound(A);
      EXPECT_LE(lb, exact) << n << " " << lmin;
      EXPECT_GT(lb, exact - 1e-11 * n) << n << " " << lmin;
    }
  }
  // A singular PSD matrix: the bound is within rounding of zero, from below.
  Eigen::MatrixXd v = Eigen::MatrixXd::Ones(6, 1);
  const double lb = sdp::MinEigenvalueLowerBound(v * v.transpose());
  EXPECT_LE(lb, 0.0);
  EXPECT_GT(lb, -1e-13);
  EXPECT_EQ(sdp::MinEigenvalueLowerBound(Eigen::MatrixXd::Constant(2, 2, NAN)), -INFINITY);
}

// min / max x1 over { x in [-1, 1]^2 : r2 - x1^2 - x2^2 >= 0 }: optimum -+sqrt(r2), exact at every order.
PolyProblem Disc(bool maximize, double r2) {
  PolyProblem p;
  p.num_vars = 2;
  p.objective = Polynomial::Variable(2, 0);
  p.maximize = maximize;
  for (int i = 0; i < 2; ++i)
    p.inequalities.push_back(Polynomial::Constant(2, 1.0) - Polynomial::Variable(2, i) * Polynomial::Variable(2, i));
  p.inequalities.push_back(Polynomial::Constant(2, r2) - Polynomial::Variable(2, 0) * Polynomial::Variable(2, 0) -
                           Polynomial::Variable(2, 1) * Polynomial::Variable(2, 1));
  return p;
}

// min (x1 + x2 - 1)^2 + x1 x2 over [-1,1]^2 (indefinite): with u = x1 + x2 the minimum over x1 x2 sits at
// x1 = 1, giving (u - 1) u, minimal at u = 1/2: optimum -1/4 at (1, -1/2). Order 1 gives -2/3, order 2 is exact.
PolyProblem Bilinear() {
  PolyProblem p;
  p.num_vars = 2;
  const auto x1 = Polynomial::Variable(2, 0), x2 = Polynomial::Variable(2, 1);
  const auto s = x1 + x2 - Polynomial::Constant(2, 1.0);
  p.objective = s * s + x1 * x2;
  for (int i = 0; i < 2; ++i)
    p.inequalities.push_back(Polynomial::Constant(2, 1.0) - Polynomial::Variable(2, i) * Polynomial::Variable(2, i));
  return p;
}

struct Solved {
  sdp::SdpSummary sdp;
  sdp::VariableBounds bounds;
};

Solved Solve(const MomentRelaxation& r, const PolyProblem& p, const std::string& solver_name) {
  auto solver = sdp::MakeSolver(solver_name);
  sdp::SdpOptions o;
  o.keep_dual_matrix = true;
  return {solver->Solve(o, r.lmi()), pop::MomentVariableBounds(p, r)};
}

TEST(VerifiedBound, MomentBoundsNeedTheBoxLocalizers) {
  // Box [-1, 1]^2 alone: |y_alpha| <= 1 exactly.
  PolyProblem box = Disc(false, 0.5);
  box.inequalities.pop_back();
  MomentRelaxation rb(box, 2);
  const auto bb = pop::MomentVariableBounds(box, rb);
  ASSERT_EQ(static_cast<int>(bb.lower.size()), rb.lmi().num_vars());
  for (int i = 0; i < rb.lmi().num_vars(); ++i) {
    EXPECT_EQ(bb.lower[i], -1.0);
    EXPECT_EQ(bb.upper[i], 1.0);
  }
  // With the disc x1^2 + x2^2 <= 0.5 too, the radius sqrt(0.5) bounds every moment more tightly.
  const auto p = Disc(false, 0.5);
  MomentRelaxation r(p, 2);
  const auto b = pop::MomentVariableBounds(p, r);
  for (int i = 0; i < r.lmi().num_vars(); ++i) {
    EXPECT_LE(b.upper[i], std::sqrt(0.5) * (1 + 1e-9));
    EXPECT_GE(b.upper[i], 0.25);  // degree <= 4: at least sqrt(0.5)^4
    EXPECT_EQ(b.lower[i], -b.upper[i]);
  }
  // x1 bounded by nothing: every bound is infinite.
  PolyProblem q = p;
  q.inequalities = {p.inequalities[1]};  // only 1 - x2^2 >= 0
  MomentRelaxation rq(q, 2);
  const auto bq = pop::MomentVariableBounds(q, rq);
  for (int i = 0; i < rq.lmi().num_vars(); ++i) EXPECT_TRUE(std::isinf(bq.upper[i]));
}

TEST(VerifiedBound, KnownOptimaAreBoundedFromBelowAndCloseToTheFloatBound) {
  struct Case {
    PolyProblem p;
    int order;
    double optimum;  // of the POP, attained by the relaxation
  };
  std::vector<Case> cases = {{Disc(false, 0.5), 1, -std::sqrt(0.5)}, {Disc(false, 0.5), 3, -std::sqrt(0.5)},
                             {Disc(true, 0.3), 2, std::sqrt(0.3)}, {Bilinear(), 2, -0.25},
                             {Bilinear(), 3, -0.25}};
  for (const std::string solver_name : {"csdp", "sdpa"}) {
    for (const auto& c : cases) {
      MomentRelaxation r(c.p, c.order);
      const auto s = Solve(r, c.p, solver_name);
      ASSERT_EQ(s.sdp.status, sdp::SdpStatus::kOptimal) << s.sdp.message;
      auto solver = sdp::MakeSolver(solver_name);
      const auto v = sdp::VerifyOptimalSolve({}, {}, r.lmi(), s.bounds, s.sdp, *solver);
      ASSERT_TRUE(v.verified()) << v.message;
      const double sign = r.objective_sign();  // the LMI minimises sign * f
      // Verified lower bound of min sign*f is below sign * optimum, within 1e-6 of the float bound.
      EXPECT_LE(v.bound, sign * c.optimum) << solver_name << " " << v.message;
      EXPECT_LE(v.bound, s.sdp.lower_bound + 1e-15) << v.message;
      EXPECT_LT(v.correction, 1e-6) << v.message;
      EXPECT_GE(v.correction, 0.0);
      EXPECT_NEAR(v.bound, sign * c.optimum, 1e-5) << v.message;
    }
  }
}

TEST(VerifiedBound, PerturbedMultiplierGivesLooserButValidBound) {
  const auto p = Disc(false, 0.5);
  MomentRelaxation r(p, 2);
  const auto s = Solve(r, p, "sdpa");
  ASSERT_EQ(s.sdp.status, sdp::SdpStatus::kOptimal);
  const auto base = sdp::VerifyLowerBound(r.lmi(), s.sdp.X, s.bounds, s.sdp.lower_bound);
  ASSERT_TRUE(base.verified());
  std::mt19937 rng(3);
  std::normal_distribution<double> N(0.0, 1.0);
  double previous = base.bound;
  for (double size : {1e-6, 1e-4, 1e-2}) {
    auto X = s.sdp.X;
    for (auto& B : X) {
      Eigen::MatrixXd P(B.rows(), B.cols());
      for (Eigen::Index i = 0; i < P.size(); ++i) P.data()[i] = N(rng);
      B += size * (P + P.transpose()) / 2;
    }
    const auto v = sdp::VerifyLowerBound(r.lmi(), X, s.bounds, s.sdp.lower_bound);
    ASSERT_TRUE(v.verified()) << v.message;
    EXPECT_LE(v.bound, -std::sqrt(0.5)) << size;  // still valid
    EXPECT_LT(v.bound, previous) << size;        // looser with a larger perturbation
    EXPECT_GT(v.correction, size) << v.message;  // the correction grows at least like the perturbation
    previous = v.bound;
  }
  // A multiplier scaled up pretends a better bound (F_0 . X grows); the residuals catch it.
  auto X = s.sdp.X;
  for (auto& B : X) B *= 1.5;
  const auto v = sdp::VerifyLowerBound(r.lmi(), X, s.bounds, s.sdp.lower_bound);
  EXPECT_TRUE(!v.verified() || v.bound <= -std::sqrt(0.5)) << v.message;
  // The repairs: residual damage (X scaled by 1 + 1e-5) is undone by the projection onto the equalities without
  // a re-solve; indefinite damage (1e-5 noise) needs the perturbed re-solve. Both end verified, valid and close.
  auto solver = sdp::MakeSolver("sdpa");
  sdp::SdpSummary scaled = s.sdp;
  for (auto& B : scaled.X) B *= 1.0 + 1e-5;
  const auto ws = sdp::VerifyOptimalSolve({}, {}, r.lmi(), s.bounds, scaled, *solver);
  ASSERT_TRUE(ws.verified()) << ws.message;
  EXPECT_EQ(ws.resolves, 0) << ws.message;
  EXPECT_LE(ws.bound, -std::sqrt(0.5));
  // The projected X is dual feasible to rounding, so what remains is its own (lower) objective: F_0 . X moved by
  // about 1e-5 * |F_0 . X| = 7e-6, and the projection never does worse than the damaged X as it is.
  EXPECT_LT(ws.correction, 1e-5) << ws.message;
  EXPECT_LE(ws.residual_term, 0.0);
  EXPECT_GT(ws.residual_term, -1e-12) << ws.message;
  const auto raw = sdp::VerifyLowerBound(r.lmi(), scaled.X, s.bounds, s.sdp.lower_bound);
  EXPECT_GE(ws.bound, raw.bound);
  sdp::SdpSummary noisy = s.sdp;
  for (auto& B : noisy.X) {
    Eigen::MatrixXd P(B.rows(), B.cols());
    for (Eigen::Index i = 0; i < P.size(); ++i) P.data()[i] = N(rng);
    B += 1e-5 * (P + P.transpose()) / 2;
  }
  const auto wn = sdp::VerifyOptimalSolve({}, {}, r.lmi(), s.bounds, noisy, *solver);
  ASSERT_TRUE(wn.verified()) << wn.message;
  EXPECT_LE(wn.bound, -std::sqrt(0.5));
  EXPECT_LT(wn.correction, 1e-6) << wn.message;
  // Without a-priori bounds on the variables, nonzero residuals cannot be bounded: unverified.
  const auto none = sdp::VariableBounds::Uniform(r.lmi().num_vars(), -INFINITY, INFINITY);
  EXPECT_FALSE(sdp::VerifyLowerBound(r.lmi(), s.sdp.X, none, s.sdp.lower_bound).verified());
}

TEST(VerifiedBound, IllConditionedRelaxationsAreNeverWronglyVerified) {
  // (a) No Slater point: { x in [-1,1]^2 : -(x1 - 0.5)^2 >= 0, -(x2 + 0.25)^2 >= 0 } is one point; the
  //     relaxation's feasible set has no interior, its dual optimum is not attained. min x1 + x2 = 0.25.
  PolyProblem p;
  p.num_vars = 2;
  const auto x1 = Polynomial::Variable(2, 0), x2 = Polynomial::Variable(2, 1);
  for (int i = 0; i < 2; ++i)
    p.inequalities.push_back(Polynomial::Constant(2, 1.0) - Polynomial::Variable(2, i) * Polynomial::Variable(2, i));
  const auto a = x1 - Polynomial::Constant(2, 0.5), b = x2 + Polynomial::Constant(2, 0.25);
  p.inequalities.push_back(-(a * a));
  p.inequalities.push_back(-(b * b));
  p.objective = x1 + x2;
  // (b) Badly scaled: the same disc with constraints multiplied by 1e6 and 1e-6.
  PolyProblem q = Disc(false, 0.5);
  q.inequalities[0] = q.inequalities[0] * 1e6;
  q.inequalities[2] = q.inequalities[2] * 1e-6;
  int verified = 0;
  for (const std::string solver_name : {"csdp", "sdpa"}) {
    for (const auto& [prob, optimum] : std::vector<std::pair<PolyProblem, double>>{{p, 0.25}, {q, -std::sqrt(0.5)}}) {
      for (int order : {1, 2, 3}) {
        MomentRelaxation r(prob, order);
        const auto s = Solve(r, prob, solver_name);
        if (s.sdp.status != sdp::SdpStatus::kOptimal) continue;  // a failed solve reports no bound at all
        auto solver = sdp::MakeSolver(solver_name);
        const auto v = sdp::VerifyOptimalSolve({}, {}, r.lmi(), s.bounds, s.sdp, *solver);
        if (v.verified()) {
          ++verified;
          EXPECT_LE(v.bound, optimum) << solver_name << " order " << order << ": " << v.message;
        } else {
          EXPECT_EQ(v.status, sdp::VerifyStatus::kUnverified);
        }
      }
    }
  }
  RecordProperty("verified_ill_conditioned", verified);
}

TEST(VerifiedBound, InfeasibilityCertificates) {
  // Disc of radius^2 0.1 intersected with x1 >= 0.5: empty.
  PolyProblem p = Disc(false, 0.1);
  p.inequalities.push_back(Polynomial::Variable(2, 0) - Polynomial::Constant(2, 0.5));
  for (const std::string solver_name : {"csdp", "sdpa"}) {
    MomentRelaxation r(p, 2);
    const auto s = Solve(r, p, solver_name);
    ASSERT_EQ(s.sdp.status, sdp::SdpStatus::kInfeasible) << s.sdp.message;
    const auto v = sdp::VerifyInfeasibility(r.lmi(), s.sdp.X, s.bounds);
    EXPECT_TRUE(v.verified()) << v.message;
    EXPECT_GT(v.bound, 0.0);
    // A damaged certificate must not verify: mostly negative definite, or zero.
    auto bad = s.sdp.X;
    for (auto& B : bad) B = -B;
    EXPECT_FALSE(sdp::VerifyInfeasibility(r.lmi(), bad, s.bounds).verified());
    for (auto& B : bad) B.setZero();
    EXPECT_FALSE(sdp::VerifyInfeasibility(r.lmi(), bad, s.bounds).verified());
  }
  // A feasible problem's multiplier never certifies infeasibility.
  const auto f = Disc(false, 0.5);
  MomentRelaxation rf(f, 2);
  const auto sf = Solve(rf, f, "csdp");
  ASSERT_EQ(sf.sdp.status, sdp::SdpStatus::kOptimal);
  EXPECT_FALSE(sdp::VerifyInfeasibility(rf.lmi(), sf.sdp.X, sf.bounds).verified());
  // LP screen of { x1 - 0.5 >= 0, -x1 - 0.5 >= 0 }: empty, certificate verified.
  auto solver = sdp::MakeSolver("sdpa");
  sdp::VerifiedBound cert;
  const auto lp = pop::ScreenWithLinearProgram(
      {Polynomial::Variable(1, 0) - Polynomial::Constant(1, 0.5), -Polynomial::Variable(1, 0) - Polynomial::Constant(1, 0.5)},
      1, {}, *solver, &cert);
  EXPECT_EQ(lp.status, sdp::SdpStatus::kInfeasible) << lp.message;
  EXPECT_TRUE(cert.verified()) << cert.message;
}

TEST(VerifiedBound, ConstraintGenerationReportsTheVerifiedBound) {
  const auto core = Disc(false, 0.5);
  pop::ConstraintGenerationOptions o;
  o.order = 2;
  auto solver = sdp::MakeSolver("csdp");
  const auto r = pop::SolveWithConstraintGeneration(o, core, {}, {}, *solver);
  ASSERT_EQ(r.status, pop::RelaxationStatus::kSolved) << r.message;
  ASSERT_TRUE(r.verification.verified()) << r.verification.message;
  EXPECT_EQ(r.bound, r.verification.bound);
  EXPECT_LE(r.bound, r.float_bound);
  EXPECT_LE(r.bound, -std::sqrt(0.5));
  o.verify.enabled = false;
  const auto off = pop::SolveWithConstraintGeneration(o, core, {}, {}, *solver);
  EXPECT_EQ(off.verification.status, sdp::VerifyStatus::kNotRun);
  EXPECT_EQ(off.bound, off.float_bound);
}

TEST(VerifiedBound, EverySetMembershipEndpointCarriesItsVerification) {
  const auto ex = SimulateCeroneExample(5, 40, 31.0);
  dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  dss::HwOuterSet set(dss::CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
  dss::BoundsOptions options;
  options.order = 1;
  options.threads = 2;
  options.generation.retry_undecided_rounds = false;
  const auto s = dss::ComputeBounds(options, set);
  const auto truth = CeroneExample::TrueParameters();
  ASSERT_FALSE(s.intervals.empty());
  for (const auto& iv : s.intervals) {
    for (const auto* e : {&iv.lower, &iv.upper}) {
      if (e->status == "empty") continue;
      EXPECT_TRUE(e->verification == "verified" || e->verification == "unverified") << iv.name << " " << e->verification;
      EXPECT_GE(e->correction, 0.0) << iv.name;
    }
    const std::size_t k = std::find(s.parameter_names.begin(), s.parameter_names.end(), iv.name) - s.parameter_names.begin();
    EXPECT_LE(iv.lower.value, truth[k]);
    EXPECT_GE(iv.upper.value, truth[k]);
  }
  const auto j = s.to_json();
  for (const auto& iv : j.at("intervals")) {
    EXPECT_TRUE(iv.at("lower").contains("verification"));
    EXPECT_TRUE(iv.at("upper").contains("correction"));
  }
}

}  // namespace
}  // namespace hw
