#pragma once
// CSDP's linear operators A(X) (op_a) and A^T(y) (op_at), over a flat copy of the constraints made once per solve
// (sdp/csdp_operators.cpp).

namespace hw::sdp {

// Names the operators in a solve's details; referencing it also links csdp_operators.cpp's op_a() and op_at()
// from the static hw_sdp archive ahead of libsdp.a's own.
const char* CsdpOperators();

// Drops the flat copy of the constraints of the solve in progress; called around every easy_sdp().
void ForgetOperatorStructure();

}  // namespace hw::sdp
