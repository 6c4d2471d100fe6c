#include "dss/statuses.hpp"

namespace hw::dss {

std::string ToString(EndpointStatus s) {
  switch (s) {
    case EndpointStatus::kUnknown: return "unknown";
    case EndpointStatus::kGuaranteed: return "guaranteed";
    case EndpointStatus::kConservative: return "conservative";
    case EndpointStatus::kEmpty: return "empty";
  }
  return "unknown";
}

std::string ToString(CertificateKind k) {
  switch (k) {
    case CertificateKind::kLinearProgram: return "lp";
    case CertificateKind::kRelaxation: return "relaxation";
    case CertificateKind::kCrossedBounds: return "crossed bounds";
    case CertificateKind::kPieces: return "pieces";
  }
  return "unknown";
}

std::string ToString(OrthantStatus s) {
  switch (s) {
    case OrthantStatus::kUndecided: return "undecided";
    case OrthantStatus::kEmpty: return "empty";
    case OrthantStatus::kSolved: return "solved";
    case OrthantStatus::kFailed: return "failed (conservative fallback)";
  }
  return "unknown";
}

std::string ToString(JobStatus s) {
  switch (s) {
    case JobStatus::kSolved: return "solved";
    case JobStatus::kInfeasible: return "infeasible";
    case JobStatus::kFailed: return "failed";
    case JobStatus::kSkipped: return "skipped";
  }
  return "unknown";
}

std::string ToString(JobOrigin o) {
  switch (o) {
    case JobOrigin::kNone: return "none";
    case JobOrigin::kFinalRound: return "final round";
    case JobOrigin::kEarlierRound: return "earlier round";
    case JobOrigin::kFeasiblePointAtEdge: return "feasible point at the box edge";
    case JobOrigin::kEdgeInOtherOrthant: return "box edge reached in another orthant";
    case JobOrigin::kSignConstraint: return "orthant sign constraint";
  }
  return "unknown";
}

std::string ToString(BoundSource s) {
  switch (s) {
    case BoundSource::kFinalRound: return "final round";
    case BoundSource::kEarlierRound: return "earlier round";
    case BoundSource::kUnfinishedSolve: return "unfinished solve";
    case BoundSource::kStoppedBeyondWitness: return "stopped beyond a feasible point's value (cannot move the interval)";
    case BoundSource::kCheapOrderSkipped: return "cheap order (cannot move the interval)";
    case BoundSource::kCheapOrderTighter: return "cheap order (tighter than an order-delta job that stopped short)";
    case BoundSource::kCheapOrder: return "cheap order";
    case BoundSource::kBoxEdge: return "box edge";
    case BoundSource::kFeasiblePointAtEdge: return "feasible point at the box edge";
    case BoundSource::kEdgeInOtherOrthant: return "box edge reached in another orthant";
    case BoundSource::kSignConstraint: return "orthant sign constraint";
  }
  return "unknown";
}

JobStatus JobStatusFromString(const std::string& text) {
  return FromString(text, {JobStatus::kSolved, JobStatus::kInfeasible, JobStatus::kFailed, JobStatus::kSkipped});
}

JobOrigin JobOriginFromString(const std::string& text) {
  return FromString(text, {JobOrigin::kNone, JobOrigin::kFinalRound, JobOrigin::kEarlierRound,
                           JobOrigin::kFeasiblePointAtEdge, JobOrigin::kEdgeInOtherOrthant, JobOrigin::kSignConstraint});
}

sdp::VerifyStatus VerifyStatusFromString(const std::string& text) {
  return FromString(text, {sdp::VerifyStatus::kNotRun, sdp::VerifyStatus::kVerified, sdp::VerifyStatus::kUnverified});
}

}  // namespace hw::dss
