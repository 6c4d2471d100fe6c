// Reading a recording (t, u, y as doubles) through the shared spec (core/recording.hpp): CSV (17 digits) against
// MATLAB v5 (uncompressed and zlib-compressed) and v7.3 (HDF5) files written by libmatio. Argument 0: the format
// (0 csv, 1 v5, 2 v5 compressed, 3 v7.3); argument 1: samples. Counter: bytes of the file.
//   build/benchmarks/recording_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <matio.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "core/csv_table.hpp"
#include "core/recording.hpp"

namespace {

std::vector<double> Signal(std::size_t n, double f) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::sin(f * static_cast<double>(i)) + 1e-3 * static_cast<double>(i % 7);
  return v;
}

void WriteMat(const std::string& path, mat_ft version, matio_compression compression, const hw::CsvTable& t) {
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, version);
  for (std::size_t c = 0; c < t.names.size(); ++c) {
    std::size_t dims[2] = {t.rows(), 1};
    matvar_t* v = Mat_VarCreate(t.names[c].c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                                const_cast<double*>(t.columns[c].data()), MAT_F_DONT_COPY_DATA);
    Mat_VarWrite(mat, v, compression);
    Mat_VarFree(v);
  }
  Mat_Close(mat);
}

// The recording file of (format, samples), written once per process.
std::string File(int format, std::size_t n) {
  static const char* kExt[] = {".csv", "_v5.mat", "_v5z.mat", "_v73.mat"};
  const std::string path = (std::filesystem::temp_directory_path() / ("hw_recording_bench_" + std::to_string(n) +
                                                                      kExt[format]))
                               .string();
  if (std::filesystem::exists(path)) return path;
  hw::CsvTable t;
  std::vector<double> time(n);
  for (std::size_t i = 0; i < n; ++i) time[i] = 0.01 * static_cast<double>(i);
  t.add_column("t", time);
  t.add_column("u", Signal(n, 0.013));
  t.add_column("y", Signal(n, 0.007));
  if (format == 0) hw::write_csv(path, t, 17);
  if (format == 1) WriteMat(path, MAT_FT_MAT5, MAT_COMPRESSION_NONE, t);
  if (format == 2) WriteMat(path, MAT_FT_MAT5, MAT_COMPRESSION_ZLIB, t);
  if (format == 3) WriteMat(path, MAT_FT_MAT73, MAT_COMPRESSION_NONE, t);
  return path;
}

void BM_ReadRecording(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(1));
  const std::string path = File(static_cast<int>(state.range(0)), n);
  for (auto _ : state) {
    const auto table = hw::read_recording(path, {"u", "y"}, {"t"});
    benchmark::DoNotOptimize(table.columns.data());
    if (table.rows() != n) state.SkipWithError("wrong length");
  }
  state.counters["file_bytes"] = static_cast<double>(std::filesystem::file_size(path));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}
BENCHMARK(BM_ReadRecording)
    ->ArgsProduct({{0, 1, 2, 3}, {10000, 1000000}})
    ->ArgNames({"format", "samples"})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
