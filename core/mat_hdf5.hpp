#pragma once
// MATLAB v7.3 .mat files, which are HDF5 files, read with libhdf5 (core/mat_source.hpp).
//
// MATLAB writes each variable as a dataset (or, for structs and sparse arrays, a group) in the root group with
// a MATLAB_class attribute, transposed (MATLAB is column-major), behind a 512-byte user block holding a text
// header. Files written with h5py often differ: the attribute is a variable-length string (h5py's default for
// `ds.attrs["MATLAB_class"] = "double"`), null-padded bytes, or absent, and the header is missing. libmatio
// reads none of these (it sees no variables, or cannot open the file); this reader takes the class from the
// attribute however it is stored, or, without one, from the dataset's HDF5 type (an integer or floating-point
// dataset is a numeric variable), and finds the HDF5 data with or without a user block.
#include <memory>
#include <string>

#include "core/mat_source.hpp"

namespace hw {

// True when `path` is an HDF5 file (with or without a user block before the HDF5 signature).
bool IsHdf5File(const std::string& path);

// Opens an HDF5 .mat file; throws InputError naming the file when libhdf5 cannot open it.
std::unique_ptr<MatSource> OpenHdf5Mat(const std::string& path);

}  // namespace hw
