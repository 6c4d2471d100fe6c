// CSDP's Schur complement as hwbounds assembles it (sdp/csdp_schur.cpp, op_o): on random block structures with
// every kind of block (diagonal, small and large matrix blocks, blocks no constraint touches), the upper
// triangle of O equals tr(A_i Z^-1 A_j X) computed from dense matrices, also when the structure kept from the
// solve's first call is read again; A(X) (op_a) and A^T(y) (op_at, sdp/csdp_operators.cpp) match dense traces and sums.
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

extern "C" {
#include <csdp/declarations.h>
}

#include "sdp/csdp_operators.hpp"
#include "sdp/csdp_schur.hpp"

namespace {

using Eigen::MatrixXd;

struct Block {
  bool diagonal;
  int size;
};

// Owns CSDP's structures for one random problem.
class RandomCsdpProblem {
 public:
  RandomCsdpProblem(const std::vector<Block>& blocks, int k, unsigned seed) : blocks_(blocks), k_(k) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    const int nb = static_cast<int>(blocks.size());
    x_.resize(nb);
    zi_.resize(nb);
    xrec_.resize(nb + 1);
    zrec_.resize(nb + 1);
    for (int b = 0; b < nb; ++b) {
      const int n = blocks[b].size;
      MatrixXd g = MatrixXd::NullaryExpr(n, n, [&] { return uni(rng); });
      MatrixXd h = MatrixXd::NullaryExpr(n, n, [&] { return uni(rng); });
      x_[b] = g * g.transpose() + MatrixXd::Identity(n, n);
      zi_[b] = h * h.transpose() + MatrixXd::Identity(n, n);
      if (blocks[b].diagonal) {
        x_[b] = x_[b].diagonal().asDiagonal();
        zi_[b] = zi_[b].diagonal().asDiagonal();
        xdata_.push_back(std::vector<double>(n + 1));
        zdata_.push_back(std::vector<double>(n + 1));
        for (int p = 0; p < n; ++p) xdata_.back()[p + 1] = x_[b](p, p), zdata_.back()[p + 1] = zi_[b](p, p);
      } else {
        xdata_.push_back(std::vector<double>(x_[b].data(), x_[b].data() + n * n));
        zdata_.push_back(std::vector<double>(zi_[b].data(), zi_[b].data() + n * n));
      }
      for (auto* rec : {&xrec_[b + 1], &zrec_[b + 1]}) {
        rec->blocksize = n;
        rec->blockcategory = blocks[b].diagonal ? DIAG : MATRIX;
      }
      xrec_[b + 1].data.mat = xdata_.back().data();
      zrec_[b + 1].data.mat = zdata_.back().data();
    }
    // Constraint i touches a random subset of the blocks (the last block: none) with random sparse entries.
    a_.assign(k + 1, std::vector<MatrixXd>(nb));
    nodes_.reserve(static_cast<std::size_t>(k) * nb);
    constraints_.resize(k + 1);
    byblocks_.assign(nb + 1, nullptr);
    std::vector<struct sparseblock*> last(nb + 1, nullptr);
    for (int i = 1; i <= k; ++i) {
      struct sparseblock* prev = nullptr;
      for (int b = 0; b < nb; ++b) {
        const int n = blocks[b].size;
        a_[i][b] = MatrixXd::Zero(n, n);
        if (b == nb - 1 || uni(rng) < -0.4) continue;
        std::map<std::pair<int, int>, double> entries;
        const int count = 1 + static_cast<int>((uni(rng) + 1.0) * 3.0);
        for (int e = 0; e < count; ++e) {
          int p = static_cast<int>((uni(rng) + 1.0) / 2.0 * n) % n, q = static_cast<int>((uni(rng) + 1.0) / 2.0 * n) % n;
          if (blocks[b].diagonal) q = p;
          entries[{std::min(p, q), std::max(p, q)}] = uni(rng);
        }
        Node node;
        node.entries.push_back(0.0);
        node.i.push_back(0);
        node.j.push_back(0);
        for (const auto& [pq, v] : entries) {
          node.entries.push_back(v);
          // Either triangle may be stored: alternate to check both.
          const bool lower = (pq.first + pq.second) % 2 == 1;
          node.i.push_back((lower ? pq.second : pq.first) + 1);
          node.j.push_back((lower ? pq.first : pq.second) + 1);
          a_[i][b](pq.first, pq.second) = v;
          a_[i][b](pq.second, pq.first) = v;
        }
        nodes_.push_back(std::move(node));
        Node& stored = nodes_.back();
        stored.block = {};
        stored.block.entries = stored.entries.data();
        stored.block.iindices = stored.i.data();
        stored.block.jindices = stored.j.data();
        stored.block.numentries = static_cast<int>(entries.size());
        stored.block.blocknum = b + 1;
        stored.block.blocksize = n;
        stored.block.constraintnum = i;
        stored.block.issparse = 1;
        if (prev) prev->next = &stored.block;
        else constraints_[i].blocks = &stored.block;
        prev = &stored.block;
        if (last[b + 1]) last[b + 1]->nextbyblock = &stored.block;
        else byblocks_[b + 1] = &stored.block;
        last[b + 1] = &stored.block;
      }
    }
  }

  // O from op_o (upper triangle, 1-based, leading dimension as CSDP's sdp() uses).
  MatrixXd Assembled() {
    const int ld = k_ % 2 == 0 ? k_ + 1 : k_;
    std::vector<double> o(static_cast<std::size_t>(ld) * k_, 123.0);
    struct blockmatrix x{static_cast<int>(blocks_.size()), xrec_.data()};
    struct blockmatrix zi{static_cast<int>(blocks_.size()), zrec_.data()};
    struct blockmatrix unused{0, nullptr};
    // Outside a solve (structure copied for the call), then twice inside one, as in two iterations: the second
    // call reads the structure the first one kept. The same numbers each time.
    op_o(k_, constraints_.data(), byblocks_.data(), zi, x, o.data(), unused, unused);
    const std::vector<double> uncached = o;
    {
      const hw::sdp::CsdpSolveScope solve;
      op_o(k_, constraints_.data(), byblocks_.data(), zi, x, o.data(), unused, unused);
      EXPECT_EQ(o, uncached);
      op_o(k_, constraints_.data(), byblocks_.data(), zi, x, o.data(), unused, unused);
      EXPECT_EQ(o, uncached);
    }
    MatrixXd out = MatrixXd::Zero(k_, k_);
    for (int j = 0; j < k_; ++j)
      for (int i = 0; i <= j; ++i) out(i, j) = o[static_cast<std::size_t>(j) * ld + i];
    return out;
  }

  // A(X) from op_a(), called twice as in one solve (the second call reads the cached copy), against tr(A_i X).
  double WorstOpAError() {
    struct blockmatrix x{static_cast<int>(blocks_.size()), xrec_.data()};
    std::vector<double> got(k_ + 1), first(k_ + 1), again(k_ + 1);
    op_a(k_, constraints_.data(), x, got.data());
    {
      const hw::sdp::CsdpSolveScope solve;
      op_a(k_, constraints_.data(), x, first.data());
      op_a(k_, constraints_.data(), x, again.data());
    }
    EXPECT_EQ(got, first);
    EXPECT_EQ(got, again);
    double worst = 0.0;
    for (int i = 1; i <= k_; ++i) {
      double want = 0.0;
      for (std::size_t b = 0; b < blocks_.size(); ++b) want += (a_[i][b] * x_[b]).trace();
      worst = std::max(worst, std::abs(got[i] - want) / (1.0 + std::abs(want)));
    }
    return worst;
  }

  // A^T(y) from op_at() into a block matrix holding garbage (op_at zeroes it), against sum_i y_i A_i.
  double WorstOpAtError(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    std::vector<double> y(k_ + 1, 0.0);
    for (int i = 1; i <= k_; ++i) y[i] = i % 5 == 0 ? 0.0 : uni(rng);  // some zero multipliers, skipped by op_at
    std::vector<std::vector<double>> data;
    std::vector<struct blockrec> rec(blocks_.size() + 1);
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      const int n = blocks_[b].size;
      data.push_back(std::vector<double>(blocks_[b].diagonal ? n + 1 : n * n, 7.0));
      rec[b + 1].blocksize = n;
      rec[b + 1].blockcategory = blocks_[b].diagonal ? DIAG : MATRIX;
      rec[b + 1].data.mat = data.back().data();
    }
    const hw::sdp::CsdpSolveScope solve;  // the call inside a solve (op_a above covers both paths)
    op_at(k_, y.data(), constraints_.data(), {static_cast<int>(blocks_.size()), rec.data()});
    double worst = 0.0;
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      const int n = blocks_[b].size;
      MatrixXd want = MatrixXd::Zero(n, n);
      for (int i = 1; i <= k_; ++i) want += y[i] * a_[i][b];
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
          if (blocks_[b].diagonal && r != c) continue;
          const double got = blocks_[b].diagonal ? data[b][r + 1] : data[b][static_cast<std::size_t>(c) * n + r];
          worst = std::max(worst, std::abs(got - want(r, c)));
        }
    }
    return worst;
  }

  // tr(A_i Z^-1 A_j X) from dense matrices, upper triangle.
  MatrixXd Reference() const {
    MatrixXd out = MatrixXd::Zero(k_, k_);
    for (int i = 1; i <= k_; ++i)
      for (int j = i; j <= k_; ++j)
        for (std::size_t b = 0; b < blocks_.size(); ++b)
          out(i - 1, j - 1) += (a_[i][b] * zi_[b] * a_[j][b] * x_[b]).trace();
    return out;
  }

 private:
  struct Node {
    std::vector<double> entries;
    std::vector<int> i, j;
    struct sparseblock block;
  };
  std::vector<Block> blocks_;
  int k_;
  std::vector<MatrixXd> x_, zi_;
  std::vector<std::vector<double>> xdata_, zdata_;
  std::vector<struct blockrec> xrec_, zrec_;
  std::vector<std::vector<MatrixXd>> a_;
  std::vector<Node> nodes_;  // reserved up front: the linked lists point into it
  std::vector<struct constraintmatrix> constraints_;
  std::vector<struct sparseblock*> byblocks_;
};

TEST(CsdpSchur, EveryKindOfBlockGivesTrAiZinvAjX) {
  // Diagonal, 1 x 1, small (9), the largest small (46), large (47, 60) matrix blocks; the last one untouched.
  const std::vector<Block> blocks{{true, 7}, {false, 1}, {false, 9}, {false, 46}, {false, 47}, {false, 60}, {false, 5}};
  for (const int k : {1, 30, 31}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      RandomCsdpProblem problem(blocks, k, seed);
      const MatrixXd got = problem.Assembled(), want = problem.Reference();
      ASSERT_GT(want.cwiseAbs().maxCoeff(), 0.0);
      EXPECT_LE((got - want).cwiseAbs().maxCoeff(), 1e-11 * want.cwiseAbs().maxCoeff()) << "k " << k << " seed " << seed;
    }
  }
  EXPECT_NE(std::string(hw::sdp::CsdpSchurAssembly()).find("csdp_schur"), std::string::npos);
}

TEST(CsdpOperators, OpAAndOpAtMatchDenseTracesAndSums) {
  const std::vector<Block> blocks{{true, 7}, {false, 1}, {false, 9}, {false, 46}, {false, 60}, {false, 5}};
  for (const int k : {1, 30, 31}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      RandomCsdpProblem problem(blocks, k, seed);
      EXPECT_LE(problem.WorstOpAError(), 1e-13) << "k " << k << " seed " << seed;
      EXPECT_LE(problem.WorstOpAtError(seed), 1e-13) << "k " << k << " seed " << seed;
    }
  }
  EXPECT_NE(std::string(hw::sdp::CsdpOperators()).find("csdp_operators"), std::string::npos);
}

}  // namespace
