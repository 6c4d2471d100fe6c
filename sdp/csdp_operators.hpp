#pragma once
// CSDP's linear operators A(X) (op_a) and A^T(y) (op_at), over a flat copy of the constraints made once per solve
// (sdp/csdp_operators.cpp).

namespace hw::sdp {

// Names the operators in a solve's details; referencing it also links csdp_operators.cpp's op_a() and op_at()
// from the static hw_sdp archive ahead of libsdp.a's own.
const char* CsdpOperators();

// The calling thread's easy_sdp() call, made under CsdpMutex (csdp_backend.cpp), lies between construction and
// destruction: inside it op_o(), op_a() and op_at() keep the solve's constraint structure from their first call to
// the last (the structure of a solve does not change); any other call, on any thread (CSDP's pinfeas() and
// dinfeas() after a solve, outside the lock), copies the structure for that call only.
class CsdpSolveScope {
 public:
  CsdpSolveScope();
  ~CsdpSolveScope();
  CsdpSolveScope(const CsdpSolveScope&) = delete;
  CsdpSolveScope& operator=(const CsdpSolveScope&) = delete;
};
bool InCsdpSolveScope();

}  // namespace hw::sdp
