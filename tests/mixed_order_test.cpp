// Mixed orders (ConstraintGenerationOptions::block_order_cap): candidates get localizing blocks of a capped
// order, constraint generation converges to the capped relaxation over every candidate (its violation check
// uses the same cap), and the capped relaxation lies between the lower order and the full order.
#include <cmath>

#include <gtest/gtest.h>

#include "pop/constraint_generation.hpp"
#include "pop/moment_relaxation.hpp"

namespace hw::pop {
namespace {

Polynomial X(int i) { return Polynomial::Variable(3, i); }
Polynomial C(double c) { return Polynomial::Constant(3, c); }

// min x1 over a ball cut by bilinear inequalities (degree 2: full localizing order delta - 1).
PolyProblem Core() {
  PolyProblem p;
  p.num_vars = 3;
  p.objective = X(0);
  p.inequalities = {C(1.0) - X(0) * X(0) - X(1) * X(1) - X(2) * X(2)};
  return p;
}

std::vector<Polynomial> Candidates() {
  return {X(0) * X(1) + X(2) - C(0.2), X(0) + X(1) * X(2) * 2.0 + C(0.1), X(1) * X(2) - X(0) * X(0) + C(0.05),
          X(0) * X(2) + X(1) - C(0.1), C(0.3) + X(0) - X(1) * X(1)};
}

double Generated(int order, int cap) {
  ConstraintGenerationOptions o;
  o.order = order;
  o.block_order_cap = cap;
  o.add_per_round = 1;
  o.verify.enabled = false;
  auto solver = sdp::MakeSolver("csdp");
  const auto r = SolveWithConstraintGeneration(o, Core(), Candidates(), {}, *solver);
  EXPECT_EQ(r.status, RelaxationStatus::kSolved) << r.message;
  EXPECT_TRUE(r.tight) << "order " << order << " cap " << cap << ": " << r.message;
  return r.bound;
}

// Every candidate as a block of localizing order min(full, cap) (cap -1: full), solved directly.
double Direct(int order, int cap) {
  PolyProblem p = Core();
  std::vector<int> orders(p.inequalities.size(), -1);
  for (const auto& g : Candidates()) {
    p.inequalities.push_back(g);
    orders.push_back(cap);
  }
  const MomentRelaxation relaxation(p, order, orders);
  auto solver = sdp::MakeSolver("csdp");
  const auto s = solver->Solve({}, relaxation.lmi());
  EXPECT_EQ(s.status, sdp::SdpStatus::kOptimal);
  return relaxation.objective_sign() * s.lower_bound;
}

TEST(MixedOrder, GenerationConvergesToTheCappedRelaxation) {
  const double capped = Generated(3, 1);
  EXPECT_NEAR(capped, Direct(3, 1), 1e-6);
  const double full = Generated(3, -1);
  EXPECT_NEAR(full, Direct(3, -1), 1e-6);
  // Between the orders: at least the order-2 bound (its blocks are all in the capped relaxation), at most the
  // full order-3 bound (the capped blocks are principal submatrices of the full ones).
  const double order2 = Generated(2, -1);
  EXPECT_GE(capped, order2 - 1e-6);
  EXPECT_LE(capped, full + 1e-6);
}

TEST(MixedOrder, ACapBelowMinusOneIsRefused) {
  ConstraintGenerationOptions o;
  o.block_order_cap = -2;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("-1 (full order)"), std::string::npos) << error;
  EXPECT_TRUE(ValidBlockOrderCap(-1, &error));
  EXPECT_TRUE(ValidBlockOrderCap(2, &error));
}

}  // namespace
}  // namespace hw::pop
