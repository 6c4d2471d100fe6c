#pragma once
// CSDP's Schur complement assembly (op_o), replaced by block kernels suited to moment relaxations
// (sdp/csdp_schur.cpp; docs/sdp.md "Schur complement").

namespace hw::sdp {

// Names the assembly in a solve's details; referencing it also links csdp_schur.cpp's op_o() from the static
// hw_sdp archive ahead of libsdp.a's own.
const char* CsdpSchurAssembly();

// Drops the constraint structure op_o() keeps for the solve in progress (by CsdpSolveScope, csdp_operators.hpp).
void ForgetSchurStructure();

}  // namespace hw::sdp
