#pragma once
// The byte layout of MATLAB v4 and v5 files, checked before libmatio reads them. libmatio reads a variable's
// samples as its header describes them: from a file cut short it returns zeros past the end, and from a damaged
// dimension it allocates what the header claims (gigabytes for a 1 kB file). So every variable must lie inside
// the file and, where its data are stored uncompressed, hold exactly the samples its dimensions claim.
// (v7.3 files are HDF5 files, read by core/mat_hdf5.cpp.)
#include <string>

namespace hw {

// The MATLAB format a file's first bytes announce: 0x0100 (v5, v7) or 0x0200 (v7.3) from its 128-byte header,
// 0 when there is no such header (a v4 file has none).
int MatHeaderVersion(const std::string& path);

// Throw InputError naming the file, the byte offset, the variable (when its name can be read) and what is wrong.
void CheckMatV4Layout(const std::string& path);
void CheckMatV5Layout(const std::string& path);

}  // namespace hw
