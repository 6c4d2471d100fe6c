// Bounds over a split prior box (dss/box_split.hpp): the pieces cover the box, the hull over the pieces keeps
// the guarantees (the weakest status and verification of the pieces it rests on), a piece proven empty drops out,
// and a run over pieces contains the truth as the whole-box run does.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "dss/box_split.hpp"
#include "tests/seeded_example.hpp"

namespace hw::dss {
namespace {

const std::vector<std::string> kNames = {"p", "q", "r"};
const ParameterBox kBox = {{-1, 1}, {0, 4}, {-2, 2}};

TEST(BoxPieces, CutsOfTwoParametersMultiplyAndCoverTheBox) {
  const auto pieces = BoxPieces(kBox, {{"q", {3, 1}}, {"r", {0}}}, kNames);
  ASSERT_EQ(pieces.size(), 6u);  // 3 slabs of q times 2 of r, q varying slowest
  const std::vector<std::pair<double, double>> q = {{0, 1}, {0, 1}, {1, 3}, {1, 3}, {3, 4}, {3, 4}};
  const std::vector<std::pair<double, double>> r = {{-2, 0}, {0, 2}, {-2, 0}, {0, 2}, {-2, 0}, {0, 2}};
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    EXPECT_EQ(pieces[k][0], kBox[0]) << k;
    EXPECT_EQ(pieces[k][1], q[k]) << k;
    EXPECT_EQ(pieces[k][2], r[k]) << k;
  }
  EXPECT_EQ(BoxPieces(kBox, {}, kNames), std::vector<ParameterBox>{kBox});
}

TEST(BoxPieces, BadCutsAreNamed) {
  std::string error;
  EXPECT_TRUE(ValidBoxCuts({{"q", {1, 2}}, {"p", {0}}}, kNames, kBox, &error)) << error;
  const std::vector<std::pair<std::vector<BoxCut>, std::string>> bad = {
      {{{"s", {0}}}, "no parameter 's'; the parameters are: p, q, r"},
      {{{"q", {4}}}, "the cut q = 4 is not strictly inside its prior box side [0, 4]"},
      {{{"q", {-1}}}, "not strictly inside"},
      {{{"q", {1}}, {"q", {2}}}, "'q' is cut twice"},
      {{{"q", {2, 2}}}, "the cut q = 2 is given twice"},
      {{{"q", {}}}, "no cut point for 'q'"},
      {{{"p", {std::nan("")}}}, "not strictly inside"},
  };
  for (const auto& [cuts, message] : bad) {
    error.clear();
    EXPECT_FALSE(ValidBoxCuts(cuts, kNames, kBox, &error)) << message;
    EXPECT_NE(error.find(message), std::string::npos) << error;
  }
}

// A piece's summary with one interval [lo, hi] of "p" and one orthant of the given status.
BoundsSummary Piece(double lo, double hi, const std::string& orthant_status, const std::string& verification = "verified") {
  BoundsSummary s;
  s.parameter_names = kNames;
  s.orthants_total = 1;
  OrthantReport o{0, "p+", orthant_status, std::nullopt};
  if (orthant_status.rfind("empty", 0) == 0) {
    o.certificate = EmptinessCertificate{"relaxation", 2, false, verification == "verified"};
    s.orthants_empty = 1;
  } else {
    s.orthants_solved = 1;
  }
  s.orthants.push_back(o);
  ParameterInterval iv;
  iv.name = "p";
  iv.lower = {lo, "guaranteed", "", 0, true, verification, 0.0};
  iv.upper = {hi, "guaranteed", "", 0, true, verification, 0.0};
  s.intervals.push_back(iv);
  s.sdp_jobs = 3;
  return s;
}

TEST(CombinePieces, HullOverTheLivePiecesWithTheWeakestStatus) {
  BoundsSummary a = Piece(-0.5, 0.1, "solved");
  BoundsSummary b = Piece(0.0, 0.7, "solved");
  b.intervals[0].upper.status = "conservative";
  b.intervals[0].upper.note = "fallback";
  const BoundsSummary empty = Piece(-9, 9, "empty (order 2)");  // proven empty: its endpoints do not count
  const auto hull = CombinePieces({a, empty, b}, kBox);
  ASSERT_EQ(hull.intervals.size(), 1u);
  EXPECT_EQ(hull.intervals[0].lower.value, -0.5);
  EXPECT_EQ(hull.intervals[0].upper.value, 0.7);
  EXPECT_EQ(hull.intervals[0].lower.status, "guaranteed");
  EXPECT_EQ(hull.intervals[0].upper.status, "conservative");
  EXPECT_EQ(hull.intervals[0].upper.note, "piece 3: fallback");
  EXPECT_EQ(hull.sdp_jobs, 9);
  EXPECT_EQ(hull.pieces.size(), 3u);
  EXPECT_TRUE(hull.pieces[1].at("invalidated").get<bool>());
  EXPECT_EQ(hull.orthants_solved, 1);  // solved in two pieces
  EXPECT_FALSE(hull.invalidated());
  EXPECT_EQ(hull.box, kBox);

  // One piece's floating-point bound that verification could not prove makes the hull's endpoint unverified.
  const BoundsSummary c = Piece(-0.2, 0.2, "solved", "unverified");
  const auto mixed = CombinePieces({a, c}, kBox);
  EXPECT_EQ(mixed.intervals[0].lower.verification, "unverified");
  EXPECT_FALSE(mixed.all_guaranteed());
}

TEST(CombinePieces, EveryPieceEmptyInvalidatesTheModelWithAVerifiedCertificateOnlyIfAllAre) {
  const auto all = CombinePieces({Piece(0, 0, "empty (LP)"), Piece(0, 0, "empty (order 2)")}, kBox);
  EXPECT_TRUE(all.invalidated());
  ASSERT_TRUE(all.orthants[0].certificate);
  EXPECT_EQ(all.orthants[0].certificate->kind, "pieces");
  EXPECT_TRUE(all.orthants[0].certificate->verified);
  EXPECT_EQ(all.orthants[0].status, "empty in every piece (up to order 2)");
  const auto weak = CombinePieces({Piece(0, 0, "empty (LP)"), Piece(0, 0, "empty (order 2)", "off")}, kBox);
  EXPECT_FALSE(weak.orthants[0].certificate->verified);
}

TEST(LargestUnwitnessedPart, TheWidestSideNoCertifiedPointReaches) {
  BoundsSummary s = Piece(-1.0, 3.0, "solved");
  EXPECT_FALSE(LargestUnwitnessedPart(s)) << "no witnessed range, no part";
  s.intervals[0].witnessed_lower = 0.0;  // [-1, 0) unwitnessed: 25 % of the width 4
  s.intervals[0].witnessed_upper = 2.5;  // (2.5, 3] unwitnessed: 12.5 %
  const auto part = LargestUnwitnessedPart(s);
  ASSERT_TRUE(part);
  EXPECT_EQ(part->parameter, "p");
  EXPECT_TRUE(part->below);
  EXPECT_EQ(part->bound, -1.0);
  EXPECT_EQ(part->witnessed, 0.0);
  EXPECT_DOUBLE_EQ(part->fraction, 0.25);
  s.intervals[0].witnessed_upper = 1.0;  // now the upper side is the larger: (1, 3], 50 %
  EXPECT_FALSE(LargestUnwitnessedPart(s)->below);
  EXPECT_DOUBLE_EQ(LargestUnwitnessedPart(s)->fraction, 0.5);
}

TEST(ProvenBox, OnlyVerifiedEndpointsShrinkTheBox) {
  BoundsSummary s = Piece(-0.5, 0.25, "solved");
  EXPECT_EQ(ProvenBox(s, kBox), (ParameterBox{{-0.5, 0.25}, {0, 4}, {-2, 2}}));  // q, r: not computed, kept
  s.intervals[0].upper.verification = "unverified";  // a floating-point bound proves nothing
  EXPECT_EQ(ProvenBox(s, kBox), (ParameterBox{{-0.5, 1}, {0, 4}, {-2, 2}}));
  s.intervals[0].lower.verification = "off";
  EXPECT_EQ(ProvenBox(s, kBox), kBox);
  const BoundsSummary point = Piece(0.5, 0.5, "solved");  // no box side of width 0
  EXPECT_EQ(ProvenBox(point, kBox), kBox);
  EXPECT_EQ(ProvenBox(Piece(0, 0, "empty (LP)"), kBox), kBox);
}

TEST(AutoSplit, TheCutLiesBeyondTheWitnessAndEarlierCutsOutsideTheBoxGo) {
  BoundsSummary s = Piece(-1.0, 3.0, "solved");
  s.intervals[0].witnessed_lower = 0.0;
  s.intervals[0].witnessed_upper = 1.0;
  const auto part = LargestUnwitnessedPart(s);  // (1, 3]
  ASSERT_TRUE(part);
  EXPECT_DOUBLE_EQ(CutBeyondWitness(*part, s, 0.02), 1.08);  // 2 % of the width 4 above the witness
  const UnwitnessedPart lower{"p", true, -1.0, 0.0, 0.25};
  EXPECT_DOUBLE_EQ(CutBeyondWitness(lower, s, 0.05), -0.2);

  const ParameterBox shrunk = {{-0.5, 0.9}, {0, 4}, {-2, 2}};
  const auto cuts = WithCut({{"p", {-0.8, 0.5}}, {"q", {1}}}, "p", 0.2, shrunk, kNames);
  ASSERT_EQ(cuts.size(), 2u);
  EXPECT_EQ(cuts[0].parameter, "p");
  EXPECT_EQ(cuts[0].values, (std::vector<double>{0.5, 0.2}));  // -0.8 lies outside the shrunk side
  EXPECT_EQ(cuts[1].values, (std::vector<double>{1}));
  EXPECT_TRUE(WithCut({{"p", {-0.8}}}, "p", 0.95, shrunk, kNames).empty()) << "no cut point left inside";
  const auto again = WithCut(cuts, "p", 0.2, shrunk, kNames);
  EXPECT_EQ(again[0].values, cuts[0].values);
  EXPECT_EQ(WithCut({}, "r", 0.0, kBox, kNames).at(0).values, std::vector<double>{0.0});
}

TEST(AutoSplit, RoundsAndOptionsAreChecked) {
  std::string error;
  EXPECT_TRUE(ValidAutoSplitRounds(5, "fork", &error)) << error;
  EXPECT_TRUE(ValidAutoSplitRounds(0, "mpi", &error)) << error;
  EXPECT_FALSE(ValidAutoSplitRounds(6, "fork", &error));
  EXPECT_EQ(error, "auto split: 6 rounds; expected 0 (off) to 5");
  EXPECT_FALSE(ValidAutoSplitRounds(-1, "fork", &error));
  EXPECT_FALSE(ValidAutoSplitRounds(1, "mpi", &error));
  EXPECT_NE(error.find("not under the mpi executor"), std::string::npos) << error;
  AutoSplitOptions o;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.margin = o.min_fraction;  // the cut-off part would hold the witness's side of the cut
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("margin"), std::string::npos) << error;
  o = AutoSplitOptions{};
  o.min_fraction = 0;
  EXPECT_FALSE(o.IsValid(&error));
}

// End to end (N = 60, n = 1, order 1: seconds): each automatic round is the split run of its cut in the box the
// round before proved, its intervals lie inside the round before's and contain the truth.
TEST(ComputeBoundsWithAutoSplit, EachRoundIsTheSplitRunOfItsCutInTheProvenBox) {
  const HwOuterSet set = SeededSet(3, 60, 1, 60.0);
  BoundsOptions options;
  options.order = 1;
  options.parameters = {"a1", "a2"};
  options.edge_witness.min_order = 1;  // certified feasible points at order 1 too: the rounds cut beyond them
  options.executor = std::make_shared<sdp::ForkExecutor>(2);
  AutoSplitOptions auto_split;
  auto_split.rounds = 2;
  const auto result = ComputeBoundsWithAutoSplit(options, set, {}, auto_split);
  const auto& rounds = result.auto_split.at("rounds");
  ASSERT_GE(rounds.size(), 2u) << "the first run leaves a part of >= 10 % unwitnessed";
  EXPECT_FALSE(result.auto_split.at("stopped").get<std::string>().empty());
  EXPECT_EQ(result.box, set.box());
  const auto first = ComputeBounds(options, set);
  const auto part = LargestUnwitnessedPart(first);
  ASSERT_TRUE(part);
  const double cut = CutBeyondWitness(*part, first, auto_split.margin);
  const auto& round1 = rounds[1];
  EXPECT_EQ(round1.at("cut").at("parameter").get<std::string>(), part->parameter);
  EXPECT_DOUBLE_EQ(round1.at("cut").at("value").get<double>(), cut);
  const auto manual =
      ComputeBoundsInPieces(options, set.WithBox(ProvenBox(first, set.box())), {{part->parameter, {cut}}});
  const auto& r1 = round1.at("intervals");
  ASSERT_EQ(r1.size(), manual.intervals.size());
  for (std::size_t i = 0; i < manual.intervals.size(); ++i) {
    EXPECT_EQ(r1[i].at("lower").get<double>(), manual.intervals[i].lower.value) << manual.intervals[i].name;
    EXPECT_EQ(r1[i].at("upper").get<double>(), manual.intervals[i].upper.value) << manual.intervals[i].name;
  }
  double narrowed = 0;
  for (std::size_t r = 1; r < rounds.size(); ++r) {
    const auto& before = rounds[r - 1].at("intervals");
    const auto& after = rounds[r].at("intervals");
    for (std::size_t i = 0; i < after.size(); ++i) {
      EXPECT_GE(after[i].at("lower").get<double>(), before[i].at("lower").get<double>()) << r << " " << i;
      EXPECT_LE(after[i].at("upper").get<double>(), before[i].at("upper").get<double>()) << r << " " << i;
      narrowed += (before[i].at("upper").get<double>() - before[i].at("lower").get<double>()) -
                  (after[i].at("upper").get<double>() - after[i].at("lower").get<double>());
    }
  }
  EXPECT_GT(narrowed, 0.0);
  // Guaranteed, verified, the truth inside, and inside the first run's intervals.
  CompareEndpoints(result, first, [](const std::string& name, std::size_t, const Endpoint& x, const Endpoint& y,
                                     bool lower) {
    if (lower) EXPECT_GE(x.value, y.value) << name;
    else EXPECT_LE(x.value, y.value) << name;
  });
  EXPECT_GT(result.sdp_jobs, first.sdp_jobs);  // counts summed over the rounds
  EXPECT_GE(result.feasible_points.size(), first.feasible_points.size());
}

// End to end on the paper's example (N = 60, n = 1, order 1: seconds): a cut at the truth of a1 and one at
// a1 = -0.5, below every point of D^ss(1) here, whose piece the engine proves empty.
TEST(ComputeBoundsInPieces, TheHullContainsTheTruthAndAnEmptyPieceDropsOut) {
  const HwOuterSet set = SeededSet(3, 60, 1, 31.0);
  BoundsOptions options;
  options.order = 1;
  options.executor = std::make_shared<sdp::ForkExecutor>(2);
  const auto whole = ComputeBounds(options, set);
  const auto split = ComputeBoundsInPieces(options, set, {{"a1", {-0.5, 1.8}}});
  ASSERT_EQ(split.pieces.size(), 3u);
  EXPECT_TRUE(split.pieces[0].at("invalidated").get<bool>());
  EXPECT_FALSE(split.pieces[1].at("invalidated").get<bool>());
  EXPECT_FALSE(split.pieces[2].at("invalidated").get<bool>());
  CompareEndpoints(split, whole, [](const std::string& name, std::size_t, const Endpoint& x, const Endpoint& y, bool) {
    EXPECT_TRUE(std::isfinite(x.value) && std::isfinite(y.value)) << name;
  });
  const std::size_t a1 = ParameterIndex(split, "a1");
  EXPECT_GE(split.intervals[a1].lower.value, -0.5);
  // Each piece's relaxation is tighter than the whole box's: a1's upper endpoint 9.96 -> 9.92 here.
  EXPECT_LT(split.intervals[a1].upper.value, whole.intervals[a1].upper.value - 0.01);
  EXPECT_EQ(split.orthants_empty, whole.orthants_empty);
  EXPECT_THROW(ComputeBoundsInPieces(options, set, {{"a1", {10.0}}}), InputError);
}

// Each piece keeps its jobs in the run directory under its own box: a rerun reads every piece back and gives the
// same numbers without a solve.
TEST(ComputeBoundsInPieces, ARerunReadsEveryPieceBackFromTheRunDirectory) {
  const HwOuterSet set = SeededSet(4, 60, 1, 31.0);
  BoundsOptions options;
  options.order = 1;
  options.parameters = {"a1", "a2"};
  options.run_dir = ::testing::TempDir() + "/box_split_resume";
  std::filesystem::remove_all(options.run_dir);
  options.executor = std::make_shared<sdp::ForkExecutor>(2);
  const std::vector<BoxCut> cuts = {{"a2", {0.5}}};
  const auto first = ComputeBoundsInPieces(options, set, cuts);
  const auto again = ComputeBoundsInPieces(options, set, cuts);
  EXPECT_GT(first.sdp_jobs, 0);
  EXPECT_EQ(again.sdp_jobs, 0);
  EXPECT_GT(again.jobs_from_cache, 0);
  ASSERT_EQ(first.intervals.size(), again.intervals.size());
  for (std::size_t i = 0; i < first.intervals.size(); ++i) {
    EXPECT_EQ(first.intervals[i].lower.value, again.intervals[i].lower.value) << first.intervals[i].name;
    EXPECT_EQ(first.intervals[i].upper.value, again.intervals[i].upper.value) << first.intervals[i].name;
  }
}

}  // namespace
}  // namespace hw::dss
