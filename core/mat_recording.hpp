#pragma once
// Recordings stored as MATLAB .mat files: v4, v5 and v7 read by libmatio, v7.3 (HDF5) by libhdf5
// (core/mat_source.hpp, core/mat_hdf5.hpp).
// A recording is a set of named vectors of one length; each variable read becomes one table column.
// Errors name the file, the variable, what is wrong and what would be right, as read_csv's do.
#include <string>
#include <vector>

#include "core/csv_table.hpp"

namespace hw {

// The table column `column` holds the .mat variable `variable`.
struct MatColumn {
  std::string column, variable;
};

// Reads every listed variable, converted to double. Each must be a real, full (not sparse), numeric
// (double, single or integer, not logical) vector -- 1xN, Nx1 or N -- of the same length N >= 1 as the
// others, and every sample must be finite. Throws InputError otherwise.
CsvTable read_mat_columns(const std::string& path, const std::vector<MatColumn>& columns);

// The file's variable names, in file order (throws InputError when the file cannot be read).
std::vector<std::string> mat_variable_names(const std::string& path);

}  // namespace hw
