// Tests of the LMI problem, the CSDP, SDPA and DSDP backends, SDPA-format I/O and the job pool.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "core/input_error.hpp"
#include "sdp/job_pool.hpp"
#include "sdp/lmi_problem.hpp"
#include "sdp/sdp_solver.hpp"
#include "sdp/sdpa_format.hpp"

extern "C" int openblas_get_num_threads();

namespace hw::sdp {
namespace {

using Kind = BlockSpec::Kind;

// min 2 y1 + 3 y2  s.t.  y1 >= 1, y2 >= 1, y1 + y2 >= 3   (one diagonal block): optimum 7 at (2, 1).
LmiProblem SmallLp() {
  LmiProblem p;
  p.blocks = {{Kind::kDiagonal, 3}};
  p.c = {2.0, 3.0};
  p.F.resize(3);
  p.add(1, 0, 0, 0, 1.0);
  p.add(1, 0, 2, 2, 1.0);
  p.add(2, 0, 1, 1, 1.0);
  p.add(2, 0, 2, 2, 1.0);
  p.add(0, 0, 0, 0, 1.0);
  p.add(0, 0, 1, 1, 1.0);
  p.add(0, 0, 2, 2, 3.0);
  return p;
}

// min y  s.t.  [[y, 1], [1, y]] >= 0: optimum 1.
LmiProblem TwoByTwo() {
  LmiProblem p;
  p.blocks = {{Kind::kPsd, 2}};
  p.c = {1.0};
  p.F.resize(2);
  p.add(1, 0, 0, 0, 1.0);
  p.add(1, 0, 1, 1, 1.0);
  p.add(0, 0, 0, 1, -1.0);
  return p;
}

// [[y, 1], [1, -y]] >= 0 has no solution (determinant -y^2 - 1 < 0).
LmiProblem InfeasibleSdp() {
  LmiProblem p;
  p.blocks = {{Kind::kPsd, 2}};
  p.c = {1.0};
  p.F.resize(2);
  p.add(1, 0, 0, 0, 1.0);
  p.add(1, 0, 1, 1, -1.0);
  p.add(0, 0, 0, 1, -1.0);
  return p;
}

// y >= 1 and y <= 0 (diagonal block).
LmiProblem InfeasibleLp() {
  LmiProblem p;
  p.blocks = {{Kind::kDiagonal, 2}};
  p.c = {1.0};
  p.F.resize(2);
  p.add(1, 0, 0, 0, 1.0);
  p.add(1, 0, 1, 1, -1.0);
  p.add(0, 0, 0, 0, 1.0);
  return p;
}

// min -y1 s.t. [[y1, y2], [y2, 1]] >= 0 and y2 >= 0: y1 can grow without limit.
LmiProblem Unbounded() {
  LmiProblem p;
  p.blocks = {{Kind::kPsd, 2}, {Kind::kDiagonal, 1}};
  p.c = {-1.0, 0.0};
  p.F.resize(3);
  p.add(1, 0, 0, 0, 1.0);
  p.add(2, 0, 0, 1, 1.0);
  p.add(2, 1, 0, 0, 1.0);
  p.add(0, 0, 1, 1, -1.0);
  return p;
}

// A strictly feasible, bounded random problem: F_0 = sum y0_i F_i - S0 with S0 > 0 (LMI strictly
// feasible) and c_i = F_i . X0 with X0 > 0 (multiplier strictly feasible), so the optimum is attained.
LmiProblem RandomProblem(unsigned seed, int m = 6) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  LmiProblem p;
  p.blocks = {{Kind::kPsd, 4}, {Kind::kDiagonal, 3}, {Kind::kPsd, 5}};
  p.F.resize(m + 1);
  std::vector<Eigen::MatrixXd> X0, S0;
  for (const auto& b : p.blocks) {
    Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(b.size, b.size, [&] { return u(rng); });
    Eigen::MatrixXd B = Eigen::MatrixXd::NullaryExpr(b.size, b.size, [&] { return u(rng); });
    Eigen::MatrixXd I = Eigen::MatrixXd::Identity(b.size, b.size);
    X0.push_back(b.kind == Kind::kPsd ? Eigen::MatrixXd(A * A.transpose() + I) : Eigen::MatrixXd((A * A.transpose() + I).diagonal().asDiagonal()));
    S0.push_back(b.kind == Kind::kPsd ? Eigen::MatrixXd(B * B.transpose() + I) : Eigen::MatrixXd((B * B.transpose() + I).diagonal().asDiagonal()));
  }
  std::vector<double> y0(m);
  for (auto& v : y0) v = u(rng);
  std::vector<Eigen::MatrixXd> F0 = S0;
  for (auto& M : F0) M = -M;
  p.c.assign(m, 0.0);
  for (int i = 1; i <= m; ++i) {
    for (int b = 0; b < static_cast<int>(p.blocks.size()); ++b) {
      const int n = p.blocks[b].size;
      Eigen::MatrixXd Fi = Eigen::MatrixXd::Zero(n, n);
      for (int r = 0; r < n; ++r)
        for (int c = r; c < n; ++c) {
          if (p.blocks[b].kind == Kind::kDiagonal && r != c) continue;
          if (u(rng) < 0.2) continue;  // some sparsity
          const double v = u(rng);
          Fi(r, c) = Fi(c, r) = v;
          p.add(i, b, r, c, v);
        }
      p.c[i - 1] += (Fi.cwiseProduct(X0[b])).sum();
      F0[b] += y0[i - 1] * Fi;
    }
  }
  for (int b = 0; b < static_cast<int>(p.blocks.size()); ++b)
    for (int r = 0; r < p.blocks[b].size; ++r)
      for (int c = r; c < p.blocks[b].size; ++c)
        if (F0[b](r, c) != 0.0 && (p.blocks[b].kind == Kind::kPsd || r == c)) p.add(0, b, r, c, F0[b](r, c));
  p.objective_offset = 0.25;
  return p;
}

// F_0 . X and F_i . X from the returned multiplier, to check the certificate independently of the solver.
double Inner(const std::vector<Entry>& F, const std::vector<Eigen::MatrixXd>& X) {
  double s = 0.0;
  for (const auto& e : F) s += e.value * X[e.block](e.row, e.col) * (e.row == e.col ? 1.0 : 2.0);
  return s;
}

class BackendTest : public ::testing::TestWithParam<std::string> {
 protected:
  SdpSummary Solve(const LmiProblem& p, const SdpOptions& o = {}) { return MakeSolver(GetParam())->Solve(o, p); }
};

TEST_P(BackendTest, LinearProgramAsDiagonalBlock) {
  const auto s = Solve(SmallLp());
  ASSERT_EQ(s.status, SdpStatus::kOptimal) << s.message;
  // DSDP returns the y its X was built from, one iterate behind its last one: here c'y = 7 + 4.1e-6 (relative
  // gap 5.9e-7, accepted under acceptable_gap = 1e-6), while its X is as accurate as the others'.
  const double y_tol = GetParam() == "dsdp" ? 1e-5 : 1e-6;
  EXPECT_NEAR(s.primal_value, 7.0, y_tol);
  EXPECT_NEAR(s.lower_bound, 7.0, 1e-6);
  EXPECT_LE(s.lower_bound, s.primal_value + 1e-7);
  ASSERT_EQ(s.y.size(), 2u);
  EXPECT_NEAR(s.y[0], 2.0, 10 * y_tol);
  EXPECT_NEAR(s.y[1], 1.0, 10 * y_tol);
  ASSERT_EQ(s.X.size(), 1u);
  EXPECT_EQ(s.X[0].rows(), 3);
  EXPECT_EQ(s.solver, GetParam());
  EXPECT_GT(s.iterations, 0);
}

TEST_P(BackendTest, TwoByTwoSdp) {
  const auto s = Solve(TwoByTwo());
  ASSERT_EQ(s.status, SdpStatus::kOptimal) << s.message;
  EXPECT_TRUE(s.usable());
  EXPECT_NEAR(s.primal_value, 1.0, 1e-6);
  EXPECT_NEAR(s.lower_bound, 1.0, 1e-6);
  EXPECT_NEAR(s.y[0], 1.0, 1e-5);
  // The multiplier is X = [[1/2, -1/2], [-1/2, 1/2]]: F_1 . X = 1 = c, F_0 . X = 1.
  EXPECT_NEAR(s.X[0](0, 1), -0.5, 1e-5);
  EXPECT_NEAR(Inner(TwoByTwo().F[1], s.X), 1.0, 1e-6);
  // Z is the slack F(y) = [[y, 1], [1, y]].
  EXPECT_NEAR(s.Z[0](0, 1), 1.0, 1e-6);
  EXPECT_NEAR(s.Z[0](0, 0), s.y[0], 1e-6);
  EXPECT_LT(s.relative_gap, 1e-6);
}

TEST_P(BackendTest, ObjectiveOffsetIsAdded) {
  auto p = TwoByTwo();
  p.objective_offset = -10.0;
  const auto s = Solve(p);
  ASSERT_TRUE(s.usable()) << s.message;
  EXPECT_NEAR(s.primal_value, -9.0, 1e-6);
  EXPECT_NEAR(s.lower_bound, -9.0, 1e-6);
}

TEST_P(BackendTest, InfeasibleLmiIsCertified) {
  for (const auto& p : {InfeasibleSdp(), InfeasibleLp()}) {
    const auto s = Solve(p);
    EXPECT_EQ(s.status, SdpStatus::kInfeasible) << s.message;
    EXPECT_FALSE(s.usable());
    // The certificate: X >= 0, F_1 . X ~ 0, F_0 . X > 0.
    ASSERT_EQ(s.X.size(), 1u);
    const double f0 = Inner(p.F[0], s.X);
    EXPECT_GT(f0, 0.0);
    EXPECT_LE(std::abs(Inner(p.F[1], s.X)), 1e-4 * f0);
  }
}

TEST_P(BackendTest, UnboundedObjective) {
  const auto s = Solve(Unbounded());
  EXPECT_EQ(s.status, SdpStatus::kUnbounded) << s.message;
  EXPECT_FALSE(s.usable());
}

TEST_P(BackendTest, IterationLimit) {
  SdpOptions o;
  o.max_iterations = 2;
  const auto s = Solve(RandomProblem(3), o);
  EXPECT_EQ(s.status, SdpStatus::kIterationLimit) << s.message;
  EXPECT_FALSE(s.usable());
  EXPECT_LE(s.iterations, 3);
  EXPECT_EQ(s.y.size(), 6u);  // a partial solution is still returned
}

TEST_P(BackendTest, RandomProblemCertificateHolds) {
  const auto p = RandomProblem(11);
  const auto s = Solve(p);
  ASSERT_TRUE(s.usable()) << s.message;
  // lower_bound really is F_0 . X + offset, and X satisfies F_i . X = c_i.
  EXPECT_NEAR(s.lower_bound, Inner(p.F[0], s.X) + p.objective_offset, 1e-6 * (1 + std::abs(s.lower_bound)));
  for (int i = 1; i <= p.num_vars(); ++i) EXPECT_NEAR(Inner(p.F[i], s.X), p.c[i - 1], 1e-6);
  for (const auto& Zb : s.Z)
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Zb).eigenvalues()(0), -1e-7);
  EXPECT_LE(s.primal_infeasibility, 1e-6);
  EXPECT_LE(s.dual_infeasibility, 1e-6);
}

TEST_P(BackendTest, ZeroVariableIsRemoved) {
  auto p = TwoByTwo();
  p.c.push_back(0.0);  // y_2 appears nowhere
  p.F.emplace_back();
  auto s = Solve(p);
  ASSERT_TRUE(s.usable()) << s.message;
  EXPECT_NEAR(s.primal_value, 1.0, 1e-6);
  ASSERT_EQ(s.y.size(), 2u);
  EXPECT_EQ(s.y[1], 0.0);
  p.c[1] = 1.0;  // now y_2 is a free variable with a cost: unbounded
  s = Solve(p);
  EXPECT_EQ(s.status, SdpStatus::kUnbounded) << s.message;
}

TEST_P(BackendTest, DuplicateEntriesAreSummed) {
  auto p = TwoByTwo();
  p.F[0].clear();
  p.add(0, 0, 0, 1, -0.5);
  p.add(0, 0, 1, 0, -0.5);  // lower-triangle input is stored upper; the two halves add up to -1
  const auto s = Solve(p);
  ASSERT_TRUE(s.usable()) << s.message;
  EXPECT_NEAR(s.primal_value, 1.0, 1e-6);
}

TEST_P(BackendTest, NoVariables) {
  LmiProblem p;
  p.blocks = {{Kind::kPsd, 2}};
  p.F.resize(1);
  p.add(0, 0, 0, 0, -1.0);  // -F_0 = diag(1, 0) >= 0
  auto s = Solve(p);
  EXPECT_EQ(s.status, SdpStatus::kOptimal) << s.message;
  p.add(0, 0, 1, 1, 1.0);  // -F_0 = diag(1, -1)
  s = Solve(p);
  EXPECT_EQ(s.status, SdpStatus::kInfeasible) << s.message;
}

TEST_P(BackendTest, InvalidInputIsRejectedBeforeTheSolve) {
  auto p = TwoByTwo();
  p.F[1].push_back({0, 2, 2, 1.0});
  auto s = Solve(p);
  EXPECT_EQ(s.status, SdpStatus::kInvalidProblem);
  EXPECT_NE(s.message.find("outside"), std::string::npos) << s.message;
  SdpOptions o;
  o.max_iterations = 0;
  s = Solve(TwoByTwo(), o);
  EXPECT_EQ(s.status, SdpStatus::kInvalidProblem);
}

TEST_P(BackendTest, QuietUnlessVerbose) {
  testing::internal::CaptureStdout();
  const auto s = Solve(RandomProblem(5));
  const std::string printed = testing::internal::GetCapturedStdout();
  EXPECT_TRUE(s.usable());
  EXPECT_EQ(printed, "");
}

TEST_P(BackendTest, ConcurrentSolvesMatchSerialOnes) {
  const int n = 8;
  std::vector<LmiProblem> problems;
  for (int k = 0; k < n; ++k) problems.push_back(RandomProblem(100 + k));
  std::vector<SdpSummary> serial(n), parallel(n);
  for (int k = 0; k < n; ++k) serial[k] = Solve(problems[k]);
  JobPoolOptions jo;
  jo.threads = 4;
  RunJobs(n, [&](std::size_t k) { parallel[k] = Solve(problems[k]); }, jo);
  for (int k = 0; k < n; ++k) {
    ASSERT_TRUE(serial[k].usable()) << serial[k].message;
    EXPECT_EQ(parallel[k].status, serial[k].status);
    EXPECT_EQ(parallel[k].iterations, serial[k].iterations);
    EXPECT_NEAR(parallel[k].lower_bound, serial[k].lower_bound, 1e-12 * (1 + std::abs(serial[k].lower_bound)));
    EXPECT_NEAR(parallel[k].primal_value, serial[k].primal_value, 1e-12 * (1 + std::abs(serial[k].primal_value)));
  }
}

TEST_P(BackendTest, BlasRunsSingleThreaded) {
  ASSERT_TRUE(Solve(TwoByTwo()).usable());
  EXPECT_EQ(openblas_get_num_threads(), 1);  // jobs are parallel in our pool, never inside BLAS
}

INSTANTIATE_TEST_SUITE_P(Backends, BackendTest, ::testing::Values("csdp", "sdpa", "dsdp"),
                         [](const auto& info) { return info.param; });

TEST(Backends, AgreeOnRandomProblems) {
  auto csdp = MakeSolver("csdp");
  auto sdpa = MakeSolver("sdpa");
  for (unsigned seed = 20; seed < 25; ++seed) {
    const auto p = RandomProblem(seed, 8);
    const auto a = csdp->Solve({}, p);
    const auto b = sdpa->Solve({}, p);
    ASSERT_TRUE(a.usable()) << a.message;
    ASSERT_TRUE(b.usable()) << b.message;
    const double scale = std::max(1.0, std::abs(a.lower_bound));
    EXPECT_NEAR(a.lower_bound, b.lower_bound, 1e-6 * scale) << "seed " << seed;
    EXPECT_NEAR(a.primal_value, b.primal_value, 1e-6 * scale) << "seed " << seed;
  }
}

TEST(Solvers, FactoryAndNames) {
  EXPECT_EQ(AvailableSolvers(), (std::vector<std::string>{"csdp", "sdpa", "dsdp"}));
  EXPECT_EQ(MakeSolver("csdp")->name(), "csdp");
  EXPECT_EQ(MakeSolver("sdpa")->name(), "sdpa");
  EXPECT_EQ(MakeSolver("dsdp")->name(), "dsdp");
  EXPECT_THROW(MakeSolver("mosek"), std::invalid_argument);
  EXPECT_EQ(ToString(SdpStatus::kOptimal), "optimal");
  EXPECT_EQ(ToString(SdpStatus::kIterationLimit), "iteration_limit");
}

TEST(LmiProblem, IsValidCatchesMalformedProblems) {
  std::string err;
  EXPECT_TRUE(TwoByTwo().IsValid(&err)) << err;
  auto p = TwoByTwo();
  p.F.pop_back();
  EXPECT_FALSE(p.IsValid(&err));
  EXPECT_NE(err.find("expected F_0..F_m"), std::string::npos) << err;
  p = TwoByTwo();
  p.F[1].push_back({1, 0, 0, 1.0});  // block 1 does not exist
  EXPECT_FALSE(p.IsValid(&err));
  p = TwoByTwo();
  p.F[1].push_back({0, 1, 0, 1.0});  // lower triangle
  EXPECT_FALSE(p.IsValid(&err));
  p = SmallLp();
  p.F[1].push_back({0, 0, 1, 1.0});  // off-diagonal entry in a diagonal block
  EXPECT_FALSE(p.IsValid(&err));
  EXPECT_NE(err.find("diagonal"), std::string::npos) << err;
  p = TwoByTwo();
  p.F[0][0].value = std::nan("");
  EXPECT_FALSE(p.IsValid(&err));
  p = TwoByTwo();
  p.c[0] = INFINITY;
  EXPECT_FALSE(p.IsValid(&err));
  p = TwoByTwo();
  p.blocks[0].size = 0;
  EXPECT_FALSE(p.IsValid(&err));
  EXPECT_EQ(TwoByTwo().nonzeros(), 3u);
}

TEST(SdpaFormat, RoundTripGivesTheSameValue) {
  const auto p = RandomProblem(7);
  const auto dir = std::filesystem::temp_directory_path() / ("hw_sdp_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "random.dat-s").string();
  WriteSdpaSparse(path, p);
  const auto q = ReadSdpaSparse(path);
  EXPECT_EQ(q.blocks.size(), p.blocks.size());
  EXPECT_EQ(q.blocks[1].kind, Kind::kDiagonal);
  EXPECT_EQ(q.c, p.c);  // %.17g round-trips doubles exactly
  EXPECT_EQ(q.nonzeros(), p.nonzeros());
  EXPECT_EQ(q.objective_offset, p.objective_offset);
  for (const std::string name : {"csdp", "sdpa"}) {
    const auto a = MakeSolver(name)->Solve({}, p);
    const auto b = MakeSolver(name)->Solve({}, q);
    ASSERT_TRUE(a.usable() && b.usable());
    EXPECT_DOUBLE_EQ(a.lower_bound, b.lower_bound);
  }
  std::filesystem::remove_all(dir);
}

// Reads the first number after `key` in a text file; NaN when absent.
double NumberAfter(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find(key);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(text.c_str() + at + key.size(), nullptr);
}

// Cross-check with the stand-alone `csdp` and `sdpa` programs on a written file. Skipped (not failed)
// where the programs are not installed: the library tests above do not depend on them.
TEST(SdpaFormat, WrittenFileAgreesWithTheSolverPrograms) {
  if (std::system("command -v csdp >/dev/null 2>&1 && command -v sdpa >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "csdp/sdpa programs not installed";
  const auto dir = std::filesystem::temp_directory_path() / ("hw_sdp_bin_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto p = RandomProblem(31, 8);
  p.objective_offset = 0.0;  // the programs do not know our offset comment
  WriteSdpaSparse((dir / "p.dat-s").string(), p);
  const std::string d = dir.string();
  ASSERT_EQ(std::system(("cd " + d + " && csdp p.dat-s p.sol > csdp.log 2>&1").c_str()), 0);
  ASSERT_EQ(std::system(("cd " + d + " && sdpa p.dat-s sdpa.out > sdpa.log 2>&1").c_str()), 0);
  const double csdp_primal = NumberAfter(d + "/csdp.log", "Primal objective value:");  // tr(F0 X): our bound
  const double csdp_dual = NumberAfter(d + "/csdp.log", "Dual objective value:");      // c'y
  const double sdpa_primal = NumberAfter(d + "/sdpa.out", "objValPrimal =");           // c'x
  const double sdpa_dual = NumberAfter(d + "/sdpa.out", "objValDual   =");             // F0 . Y
  const auto a = MakeSolver("csdp")->Solve({}, p);
  const auto b = MakeSolver("sdpa")->Solve({}, p);
  ASSERT_TRUE(a.usable() && b.usable());
  const double tol = 1e-6 * std::max(1.0, std::abs(a.lower_bound));
  EXPECT_NEAR(a.lower_bound, csdp_primal, tol);
  EXPECT_NEAR(a.primal_value, csdp_dual, tol);
  EXPECT_NEAR(b.primal_value, sdpa_primal, tol);
  EXPECT_NEAR(b.lower_bound, sdpa_dual, tol);
  std::filesystem::remove_all(dir);
}

TEST(SdpaFormat, ReadsStandardFilesWithPunctuation) {
  // The layout of SDPA's own example1.dat-s: comments, braces and commas in the header.
  const std::string text =
      "\"Example 1: mDim = 3, nBLOCK = 1, {2}\"\n"
      "   3  =  mDIM\n"
      "   1  =  nBOLCK\n"
      "   2  = bLOCKsTRUCT\n"
      "{48, -8, 20}\n"
      "0 1 1 1 -11\n0 1 2 2 23\n1 1 1 1 10\n1 1 1 2 4\n2 1 2 2 -8\n3 1 1 2 -8\n3 1 2 2 -2\n";
  const auto p = ParseSdpaSparse(text, "example1.dat-s");
  EXPECT_EQ(p.num_vars(), 3);
  EXPECT_EQ(p.c, (std::vector<double>{48, -8, 20}));
  const auto s = MakeSolver("csdp")->Solve({}, p);
  ASSERT_TRUE(s.usable()) << s.message;
  EXPECT_NEAR(s.primal_value, -41.9, 1e-6 * 41.9);  // the `sdpa` binary: objValPrimal = -4.19e+01
  EXPECT_NEAR(s.lower_bound, -41.9, 1e-6 * 41.9);
}

TEST(SdpaFormat, ReaderErrorsNameFileAndLine) {
  auto expect_error = [](const std::string& text, const std::string& where, const std::string& what) {
    try {
      ParseSdpaSparse(text, "bad.dat-s");
      ADD_FAILURE() << "no error for: " << text;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(where), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
  };
  const std::string header = "1\n1\n2\n1.0\n";
  expect_error(header + "0 1 1 1 1.0\n1 1 1 x 1.0\n", "bad.dat-s:6:", "matno blkno i j value");
  expect_error(header + "0 2 1 1 1.0\n", "bad.dat-s:5:", "block number 2");
  expect_error(header + "0 1 3 1 1.0\n", "bad.dat-s:5:", "outside");
  expect_error(header + "5 1 1 1 1.0\n", "bad.dat-s:5:", "matrix number 5");
  expect_error("1\n1\n-2\n1.0\n0 1 1 2 1.0\n", "bad.dat-s:5:", "diagonal");
  expect_error("1\n1\n0\n", "bad.dat-s:3:", "block sizes");
  expect_error("1\n", "bad.dat-s", "header");
  expect_error("* offset = abc\n" + header, "bad.dat-s:1:", "offset");
  EXPECT_EQ(ParseSdpaSparse("* offset = -2.5\n" + header, "ok").objective_offset, -2.5);
  EXPECT_THROW(ReadSdpaSparse("/nonexistent/x.dat-s"), InputError);
}

TEST(JobPool, RunsEveryJobOnceAndReportsProgress) {
  const std::size_t n = 50;
  std::vector<std::atomic<int>> runs(n);
  std::size_t last_done = 0, calls = 0;
  bool monotone = true;
  JobPoolOptions o;
  o.threads = 3;
  o.on_progress = [&](const JobProgress& p) {
    monotone = monotone && p.done == last_done + 1 && p.total == n && p.eta_seconds >= 0;
    last_done = p.done;
    ++calls;
  };
  RunJobs(n, [&](std::size_t i) { runs[i]++; }, o);
  for (const auto& r : runs) EXPECT_EQ(r.load(), 1);
  EXPECT_EQ(calls, n);
  EXPECT_TRUE(monotone);
  EXPECT_EQ(last_done, n);
}

TEST(JobPool, RethrowsTheFirstError) {
  JobPoolOptions o;
  o.threads = 2;
  EXPECT_THROW(RunJobs(
                   20, [](std::size_t i) { if (i == 3) throw std::runtime_error("job 3 failed"); }, o),
               std::runtime_error);
  RunJobs(0, [](std::size_t) { FAIL(); });
}

}  // namespace
}  // namespace hw::sdp
