// Recordings from MATLAB files and the shared recording spec (core/mat_recording.hpp, core/recording.hpp).
// Fixtures: tests/data/recording.csv and its .mat twins (tests/data/make_mat_fixtures.py: scipy.io.savemat v5,
// h5py v7.3); the bad-input files are written here with libmatio.
#include <gtest/gtest.h>
#include <matio.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/csv_table.hpp"
#include "core/mat_recording.hpp"
#include "core/recording.hpp"

namespace hw {
namespace {

const std::string kData = std::string(HW_SOURCE_DIR) + "/tests/data";

std::string Temp(const std::string& name) { return ::testing::TempDir() + "/recording_test_" + name; }

// A variable to write: class, dims and data given raw, for cases libmatio's helpers do not cover.
struct Var {
  std::string name;
  matio_classes cls = MAT_C_DOUBLE;
  matio_types type = MAT_T_DOUBLE;
  std::vector<std::size_t> dims;
  void* data = nullptr;
  int flags = 0;
};

void WriteMat(const std::string& path, mat_ft version, const std::vector<Var>& vars) {
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, version);
  ASSERT_NE(mat, nullptr) << path;
  for (const auto& v : vars) {
    std::vector<std::size_t> dims = v.dims;
    matvar_t* m =
        Mat_VarCreate(v.name.c_str(), v.cls, v.type, static_cast<int>(dims.size()), dims.data(), v.data, v.flags);
    ASSERT_NE(m, nullptr) << v.name;
    ASSERT_EQ(Mat_VarWrite(mat, m, MAT_COMPRESSION_NONE), 0) << v.name;
    Mat_VarFree(m);
  }
  Mat_Close(mat);
}

Var Column(const std::string& name, std::vector<double>& data) {
  return {name, MAT_C_DOUBLE, MAT_T_DOUBLE, {data.size(), 1}, data.data()};
}

// The message of the InputError `f` throws ("" when it does not throw).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << "message: " << (text)

void ExpectSameSamples(const CsvTable& got, const CsvTable& csv, const std::vector<std::string>& names) {
  for (const auto& n : names) {
    ASSERT_TRUE(got.has(n)) << n;
    EXPECT_EQ(got.column(n), csv.column(n)) << n;  // exact: every value was written with all its digits
  }
}

TEST(MatRecording, ScipyV5FileReadsLikeItsCsvTwin) {
  const CsvTable csv = read_csv(kData + "/recording.csv");
  ASSERT_EQ(csv.rows(), 40u);
  const CsvTable mat = read_recording(kData + "/recording_v5.mat:u=vir,y=qm,t=time", {"u", "y"}, {"t"});
  EXPECT_EQ(mat.rows(), 40u);
  ExpectSameSamples(mat, csv, {"t", "u", "y"});
}

TEST(MatRecording, H5pyV73FileReadsLikeItsCsvTwin) {
  const CsvTable csv = read_csv(kData + "/recording.csv");
  const CsvTable mat = read_recording(kData + "/recording_v73.mat:u=vir,y=qm,t=time", {"u", "y"}, {"t"});
  ExpectSameSamples(mat, csv, {"t", "u", "y"});
}

TEST(MatRecording, LibmatioV73AndV5FilesReadLikeTheirCsvTwin) {
  const CsvTable csv = read_csv(kData + "/recording.csv");
  auto t = csv.column("t"), u = csv.column("u"), y = csv.column("y");
  for (mat_ft version : {MAT_FT_MAT73, MAT_FT_MAT5}) {
    const std::string path = Temp(version == MAT_FT_MAT73 ? "libmatio73.mat" : "libmatio5.mat");
    WriteMat(path, version,
             {Column("t", t), Column("u", u), {"y", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, y.size()}, y.data()}});
    // No map: the variables carry the column names.
    ExpectSameSamples(read_recording(path, {"u", "y"}, {"t"}), csv, {"t", "u", "y"});
  }
}

TEST(MatRecording, IntegerAndSingleVariablesBecomeDoubles) {
  std::vector<std::int16_t> counts = {-3, 0, 7};
  std::vector<float> volts = {0.5f, -1.25f, 2.0f};
  const std::string path = Temp("classes.mat");
  WriteMat(path, MAT_FT_MAT5,
           {{"counts", MAT_C_INT16, MAT_T_INT16, {3, 1}, counts.data()},
            {"volts", MAT_C_SINGLE, MAT_T_SINGLE, {1, 3}, volts.data()}});
  const auto table = read_recording(path + ":u=counts,y=volts", {"u", "y"});
  EXPECT_EQ(table.column("u"), (std::vector<double>{-3, 0, 7}));
  EXPECT_EQ(table.column("y"), (std::vector<double>{0.5, -1.25, 2.0}));
}

TEST(MatRecording, OptionalColumnMayBeAbsentAndOnlyAskedColumnsAreRead) {
  std::vector<double> u = {1, 2, 3}, y = {4, 5, 6}, other = {7, 8};
  const std::string path = Temp("optional.mat");
  WriteMat(path, MAT_FT_MAT5, {Column("u", u), Column("y", y), Column("other", other)});
  const auto table = read_recording(path, {"u", "y"}, {"t"});
  EXPECT_FALSE(table.has("t"));
  EXPECT_FALSE(table.has("other"));  // a variable of another length is not part of this recording
  EXPECT_EQ(table.column("y"), y);
}

// --- bad input: every case names the file and the variable, and says what is wrong -----------------------

TEST(MatRecordingErrors, MissingVariableListsTheFileContents) {
  const std::string path = kData + "/recording_v5.mat";
  const auto e = ErrorOf([&] { read_recording(path + ":u=vin,y=qm", {"u", "y"}); });
  EXPECT_HAS(e, path);
  EXPECT_HAS(e, "no variable 'vin'");
  EXPECT_HAS(e, "vir (40x1 double)");
  EXPECT_HAS(e, "qm (1x40 double)");
}

TEST(MatRecordingErrors, UnmappedRequiredColumnSaysHowToMapIt) {
  const std::string path = kData + "/recording_v73.mat";
  const auto e = ErrorOf([&] { read_recording(path + ":u=vir", {"u", "y"}); });
  EXPECT_HAS(e, "no variable 'y' for the column y");
  EXPECT_HAS(e, path + ":y=VARIABLE");
  EXPECT_HAS(e, "qm");
}

// The bad-input cases below are written as v5 files (read by libmatio) and as v7.3 files (HDF5, read by
// libhdf5: core/mat_hdf5.cpp); both readers describe a variable alike, so the messages are the same.
const mat_ft kVersions[] = {MAT_FT_MAT5, MAT_FT_MAT73};

std::string Temp(const std::string& name, mat_ft version) {
  return Temp((version == MAT_FT_MAT73 ? "v73_" : "v5_") + name);
}

TEST(MatRecordingErrors, MatrixIsTheWrongShape) {
  std::vector<double> m(12, 1.0);
  for (mat_ft version : kVersions) {
    const std::string path = Temp("matrix.mat", version);
    WriteMat(path, version, {{"m", MAT_C_DOUBLE, MAT_T_DOUBLE, {3, 4}, m.data()}});
    const auto e = ErrorOf([&] { read_recording(path + ":u=m", {"u"}); });
    EXPECT_HAS(e, path + ": variable 'm' is a 3x4 double array");
    EXPECT_HAS(e, "must be a vector (1xN or Nx1)");
  }
}

TEST(MatRecordingErrors, EmptyVariableHasNoSamples) {
  for (mat_ft version : kVersions) {
    const std::string path = Temp("empty.mat", version);
    WriteMat(path, version, {{"e", MAT_C_DOUBLE, MAT_T_DOUBLE, {0, 0}, nullptr}});
    const auto e = ErrorOf([&] { read_recording(path + ":u=e", {"u"}); });
    EXPECT_HAS(e, "variable 'e' is a 0x0");
    EXPECT_HAS(e, "at least one sample");
  }
}

TEST(MatRecordingErrors, CharLogicalComplexSparseAreNotNumericSignals) {
  char text[] = "hello";
  std::vector<std::uint8_t> flags = {1, 0, 1};
  std::vector<double> re = {1, 2, 3}, im = {0, 1, 0};
  mat_complex_split_t z{re.data(), im.data()};
  std::vector<double> sdata = {1.0, 2.0};
  std::vector<mat_uint32_t> ir = {0, 2}, jc = {0, 2};
  mat_sparse_t sparse{2, ir.data(), 2, jc.data(), 2, 2, sdata.data()};
  for (mat_ft version : kVersions) {
    const std::string path = Temp("kinds.mat", version);
    WriteMat(path, version,
             {{"name", MAT_C_CHAR, MAT_T_UTF8, {1, 5}, text},
              {"flags", MAT_C_UINT8, MAT_T_UINT8, {3, 1}, flags.data(), MAT_F_LOGICAL},
              {"z", MAT_C_DOUBLE, MAT_T_DOUBLE, {3, 1}, &z, MAT_F_COMPLEX},
              {"s", MAT_C_SPARSE, MAT_T_DOUBLE, {3, 1}, &sparse}});
    auto e = ErrorOf([&] { read_recording(path + ":u=name", {"u"}); });
    EXPECT_HAS(e, "variable 'name' is a 1x5 char array");
    EXPECT_HAS(e, "must be numeric");
    e = ErrorOf([&] { read_recording(path + ":u=flags", {"u"}); });
    EXPECT_HAS(e, "variable 'flags' is a 3x1 logical array");
    EXPECT_HAS(e, "must be numeric");
    e = ErrorOf([&] { read_recording(path + ":u=z", {"u"}); });
    EXPECT_HAS(e, "variable 'z' is a 3x1 double array of complex numbers");
    EXPECT_HAS(e, "must be real");
    e = ErrorOf([&] { read_recording(path + ":u=s", {"u"}); });
    EXPECT_HAS(e, "variable 's' is a 3x1 sparse array");
  }
}

TEST(MatRecordingErrors, StructAndCellAreNotNumericSignals) {
  for (mat_ft version : kVersions) {
    const std::string path = Temp("containers.mat", version);
    mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, version);
    ASSERT_NE(mat, nullptr);
    std::size_t dims[2] = {1, 1};
    const char* fields[1] = {"x"};
    matvar_t* st = Mat_VarCreateStruct("rec", 2, dims, fields, 1);
    double one = 1.0;
    Mat_VarSetStructFieldByName(st, "x", 0, Mat_VarCreate("x", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &one, 0));
    Mat_VarWrite(mat, st, MAT_COMPRESSION_NONE);
    Mat_VarFree(st);
    matvar_t* cell = Mat_VarCreate("c", MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0);
    Mat_VarSetCell(cell, 0, Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &one, 0));
    Mat_VarWrite(mat, cell, MAT_COMPRESSION_NONE);
    Mat_VarFree(cell);
    Mat_Close(mat);
    auto e = ErrorOf([&] { read_recording(path + ":u=rec", {"u"}); });
    EXPECT_HAS(e, "variable 'rec' is a 1x1 struct array");
    EXPECT_HAS(e, "must be numeric");
    e = ErrorOf([&] { read_recording(path + ":u=c", {"u"}); });
    EXPECT_HAS(e, "variable 'c' is a 1x1 cell array");
    // Only the variables: MATLAB's and libmatio's internal "#refs#" group (the cell's contents) is not one.
    auto names = mat_variable_names(path);
    std::sort(names.begin(), names.end());  // v5 lists them in file order, v7.3 in name order
    EXPECT_EQ(names, (std::vector<std::string>{"c", "rec"})) << path;
  }
}

TEST(MatRecordingErrors, NonFiniteSampleIsNamedByIndex) {
  std::vector<double> u = {1, 2, NAN, 4}, y = {1, 2, 3, INFINITY};
  for (mat_ft version : {MAT_FT_MAT5, MAT_FT_MAT73}) {
    const std::string path = Temp(version == MAT_FT_MAT5 ? "nan5.mat" : "nan73.mat");
    WriteMat(path, version, {Column("u", u), Column("y", y)});
    EXPECT_HAS(ErrorOf([&] { read_recording(path, {"u"}); }),
               path + ": variable 'u' sample 3 is nan; every sample must be a finite number");
    EXPECT_HAS(ErrorOf([&] { read_recording(path + ":u=y", {"u"}); }), "variable 'y' sample 4 is inf");
  }
}

TEST(MatRecordingErrors, VariablesOfDifferentLengths) {
  std::vector<double> u = {1, 2, 3}, y = {1, 2};
  const std::string path = Temp("lengths.mat");
  WriteMat(path, MAT_FT_MAT5, {Column("u", u), Column("y", y)});
  const auto e = ErrorOf([&] { read_recording(path, {"u", "y"}); });
  EXPECT_HAS(e, "variable 'y' has 2 samples but 'u' has 3");
}

TEST(MatRecordingErrors, FileThatIsNotAMatFile) {
  const std::string path = Temp("not_really.mat");
  std::ofstream(path) << "t,u,y\n0,1,2\n";
  const auto e = ErrorOf([&] { read_recording(path, {"u"}); });
  EXPECT_HAS(e, path + ": not a MATLAB .mat file");
  EXPECT_HAS(ErrorOf([&] { read_recording(Temp("absent.mat") + ":u=x", {"u"}); }), "absent.mat: cannot open file");
}

// h5py writes a bytes attribute null-padded, not null-terminated; libmatio could not tell the class then.
TEST(MatRecording, V73FileWithANullPaddedClassReadsLikeItsCsvTwin) {
  const CsvTable csv = read_csv(kData + "/recording.csv");
  const CsvTable mat = read_recording(kData + "/recording_v73_nullpad.mat:u=vir,y=qm,t=time", {"u", "y"}, {"t"});
  ExpectSameSamples(mat, csv, {"t", "u", "y"});
}

// --- the spec itself --------------------------------------------------------------------------------------

TEST(RecordingSpec, ParsesPathAndMap) {
  auto s = RecordingSpec::Parse("runs/a:b/rec.MAT:u=vir, y = qm");
  EXPECT_EQ(s.path, "runs/a:b/rec.MAT");
  EXPECT_TRUE(s.mat);
  ASSERT_EQ(s.map.size(), 2u);
  EXPECT_EQ(s.map[1].column, "y");
  EXPECT_EQ(s.map[1].variable, "qm");
  s = RecordingSpec::Parse("data/rec.csv");
  EXPECT_FALSE(s.mat);
  EXPECT_TRUE(s.map.empty());
  s = RecordingSpec::Parse("odd:name.txt");  // no .mat / .csv map: a CSV path as given
  EXPECT_EQ(s.path, "odd:name.txt");
}

TEST(RecordingSpec, MalformedMapsAreErrors) {
  EXPECT_HAS(ErrorOf([] { RecordingSpec::Parse("rec.mat:"); }), "nothing after ':'");
  EXPECT_HAS(ErrorOf([] { RecordingSpec::Parse("rec.mat:u"); }), "'u' is not COLUMN=VARIABLE");
  EXPECT_HAS(ErrorOf([] { RecordingSpec::Parse("rec.mat:u=a,,y=b"); }), "'' is not COLUMN=VARIABLE");
  EXPECT_HAS(ErrorOf([] { RecordingSpec::Parse("rec.mat:u=a,y="); }), "'y=' is not COLUMN=VARIABLE");
  EXPECT_HAS(ErrorOf([] { RecordingSpec::Parse("rec.mat:u=a,u=b"); }), "column 'u' is mapped twice");
}

TEST(RecordingSpec, UnknownColumnInTheMapIsAnError) {
  const auto e = ErrorOf([] { read_recording(kData + "/recording_v5.mat:u=vir,z=qm", {"u", "y"}, {"t"}); });
  EXPECT_HAS(e, "unknown column 'z'");
  EXPECT_HAS(e, "this command reads u, y and optionally t");
}

TEST(RecordingSpec, CsvColumnsCanBeMappedToo) {
  const auto table = read_recording(kData + "/recording.csv:u=y,y=u", {"u", "y"});
  const auto csv = read_csv(kData + "/recording.csv");
  EXPECT_EQ(table.column("u"), csv.column("y"));
  EXPECT_EQ(table.column("y"), csv.column("u"));
  EXPECT_HAS(ErrorOf([] { read_recording(kData + "/recording.csv", {"w"}); }),
             "no column 'w'; the header has: t, u, y");
  EXPECT_HAS(ErrorOf([] { read_recording(kData + "/recording.csv:u=vir", {"u"}); }), "no column 'vir'");
}

#ifdef HW_CLI_PATH
// The CLI reads a .mat recording through the same spec: `simulate --input` gives the CSV twin's output,
// and a bad variable is a clear error with exit code 2.
TEST(MatRecordingCli, SimulateReadsTheMatFileLikeTheCsv) {
  const std::string model = Temp("model.json");
  std::ofstream(model) << R"({"type": "hammerstein_wiener", "input_nonlinearity": {"kind": "polynomial",
    "coefficients": [1, 0.3]}, "linear": {"a": [-0.5], "b": [0, 1], "delay": 0},
    "output_nonlinearity": {"kind": "identity"}})";
  const std::string cli = std::string(HW_CLI_PATH) + " simulate --model " + model + " --input ";
  ASSERT_EQ(std::system((cli + kData + "/recording.csv --out " + Temp("from_csv.csv") + " > /dev/null").c_str()), 0);
  ASSERT_EQ(
      std::system((cli + kData + "/recording_v73.mat:u=vir --out " + Temp("from_mat.csv") + " > /dev/null").c_str()),
      0);
  const auto a = read_csv(Temp("from_csv.csv")), b = read_csv(Temp("from_mat.csv"));
  EXPECT_EQ(a.column("w"), b.column("w"));
  const std::string bad = cli + kData + "/recording_v5.mat:u=nope --out " + Temp("bad.csv") + " 2> " + Temp("bad.err");
  const int rc = std::system(bad.c_str());
  ASSERT_TRUE(WIFEXITED(rc));
  EXPECT_EQ(WEXITSTATUS(rc), 2);
  std::stringstream err;
  err << std::ifstream(Temp("bad.err")).rdbuf();
  EXPECT_HAS(err.str(), "recording_v5.mat: no variable 'nope'; the file has: ");
}
#endif

}  // namespace
}  // namespace hw
