#pragma once
// The bound engine's statuses, as enums with one name each. The names are what the JSON output, the reports and
// the run cache hold, so they never change; code compares the enums, never the names.
#include <initializer_list>
#include <map>
#include <ostream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "sdp/verified_bound.hpp"  // sdp::VerifyStatus: "off", "verified", "unverified"

namespace hw::dss {

// An interval endpoint: a valid bound of D^ss(n) in the prior box from the relaxations ("guaranteed"), a valid
// bound from a fallback of a failed solve ("conservative"), or none: every orthant is proven empty ("empty").
enum class EndpointStatus { kUnknown, kGuaranteed, kConservative, kEmpty };
std::string ToString(EndpointStatus s);  // "unknown", "guaranteed", "conservative", "empty"

// How a sign orthant was proven empty (EmptinessCertificate::kind).
enum class CertificateKind { kLinearProgram, kRelaxation, kCrossedBounds, kPieces };
std::string ToString(CertificateKind k);  // "lp", "relaxation", "crossed bounds", "pieces"

// A sign orthant in a run: not decided yet, proven empty (its certificate says how), solved, or failed (its
// endpoints fell back to valid, conservative bounds).
enum class OrthantStatus { kUndecided, kEmpty, kSolved, kFailed };
std::string ToString(OrthantStatus s);  // "undecided", "empty", "solved", "failed (conservative fallback)"

// A bound job's outcome: its bound holds (solved), its relaxation is infeasible (the orthant is empty), the solve
// failed, or it was not run since its bound cannot move the endpoint (skipped; its bound is still valid).
enum class JobStatus { kSolved, kInfeasible, kFailed, kSkipped };
std::string ToString(JobStatus s);  // "solved", "infeasible", "failed", "skipped"

// Where a job's bound came from: a constraint-generation round (pop::BoundOrigin), or no solve at all: a certified
// feasible point at the box edge, the box edge reached in another orthant, or the orthant's sign constraint.
enum class JobOrigin { kNone, kFinalRound, kEarlierRound, kFeasiblePointAtEdge, kEdgeInOtherOrthant, kSignConstraint };
std::string ToString(JobOrigin o);  // "none", "final round", "earlier round", "feasible point at the box edge", ...

// Where an orthant bound entering an endpoint came from (BoundsSummary::bound_sources).
enum class BoundSource {
  kFinalRound,            // the last round of constraint generation
  kEarlierRound,          // an earlier round's verified bound, tighter than the last one's
  kUnfinishedSolve,       // the verified last iterate of a solve that stopped short
  kStoppedBeyondWitness,  // a job that ended once its bound passed a certified feasible point's value
  kCheapOrderSkipped,     // the cheap order's bound of an objective that cannot move the interval
  kCheapOrderTighter,     // the cheap order's bound, tighter than an order-delta job that stopped short
  kCheapOrder,            // the cheap order's bound of an orthant whose order-delta solve failed
  kBoxEdge,               // the orthant's box edge (every solve failed)
  kFeasiblePointAtEdge,   // a certified feasible point at the box edge
  kEdgeInOtherOrthant,    // the box edge, reached by a feasible point in another orthant
  kSignConstraint,        // the orthant's sign constraint already bounds the objective
};
std::string ToString(BoundSource s);

// JSON holds the names (nlohmann::json finds these by argument-dependent lookup).
inline void to_json(nlohmann::json& j, EndpointStatus s) { j = ToString(s); }
inline void to_json(nlohmann::json& j, CertificateKind k) { j = ToString(k); }
inline void to_json(nlohmann::json& j, OrthantStatus s) { j = ToString(s); }
inline void to_json(nlohmann::json& j, JobStatus s) { j = ToString(s); }
inline void to_json(nlohmann::json& j, JobOrigin o) { j = ToString(o); }
inline void to_json(nlohmann::json& j, BoundSource s) { j = ToString(s); }

// Streams print the names (test failure messages).
inline std::ostream& operator<<(std::ostream& os, EndpointStatus s) { return os << ToString(s); }
inline std::ostream& operator<<(std::ostream& os, CertificateKind k) { return os << ToString(k); }
inline std::ostream& operator<<(std::ostream& os, OrthantStatus s) { return os << ToString(s); }
inline std::ostream& operator<<(std::ostream& os, JobStatus s) { return os << ToString(s); }
inline std::ostream& operator<<(std::ostream& os, JobOrigin o) { return os << ToString(o); }
inline std::ostream& operator<<(std::ostream& os, BoundSource s) { return os << ToString(s); }

// The value of E named `text` (as ToString names it) among `values`: reads statuses back from JSON (the run
// cache, a worker's answer). Throws std::runtime_error on any other text, so a damaged record is never trusted.
template <typename E>
E FromString(const std::string& text, std::initializer_list<E> values) {
  for (E e : values)
    if (ToString(e) == text) return e;
  throw std::runtime_error("unknown status '" + text + "'");
}

// Counts keyed by name, in the order of the names (JSON objects and reports list them so).
template <typename E>
std::map<std::string, int> ByName(const std::map<E, int>& counts) {
  std::map<std::string, int> named;
  for (const auto& [e, n] : counts) named[ToString(e)] += n;
  return named;
}

JobStatus JobStatusFromString(const std::string& text);
JobOrigin JobOriginFromString(const std::string& text);
sdp::VerifyStatus VerifyStatusFromString(const std::string& text);

}  // namespace hw::dss
