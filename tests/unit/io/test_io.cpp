// Unit tests of the io module: atomic writes and run status of the run directory, the
// manifest environment, series.h5 round trip, snapshots.h5 + .xdmf layout (dimension order,
// x-fastest storage, padding of 2D vectors), checkpoints, resuming and comparing runs, and the
// checks that must reject bad input.
#include <H5Cpp.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/checkpoint.hpp"
#include "io/compare_runs.hpp"
#include "io/manifest.hpp"
#include "io/run_directory.hpp"
#include "io/series_writer.hpp"
#include "io/snapshot_writer.hpp"

namespace caplab::io {
namespace {

namespace fs = std::filesystem;

/// A fresh scratch directory per test, removed afterwards.
class IoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("caplab_test_io_" + std::to_string(::getpid()) + "_" +
                                        info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};
class IoRunDirectory : public IoTest {};
class IoSeries : public IoTest {};
class IoSnapshot : public IoTest {};

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    const auto ext = e.path().extension().string();
    if (ext == ".tmp" || ext == ".partial") found.push_back(e.path().filename().string());
  }
  return found;
}

/// Minimal XML well-formedness check: every element opened is closed in order.
bool tags_balanced(const std::string& xml) {
  std::vector<std::string> stack;
  std::size_t pos = 0;
  while ((pos = xml.find('<', pos)) != std::string::npos) {
    const std::size_t end = xml.find('>', pos);
    if (end == std::string::npos) return false;
    const std::string tag = xml.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty() || tag[0] == '?' || tag[0] == '!') continue;
    if (tag.back() == '/') continue;
    if (tag[0] == '/') {
      if (stack.empty() || stack.back() != tag.substr(1)) return false;
      stack.pop_back();
    } else {
      stack.push_back(tag.substr(0, tag.find_first_of(" \t\n")));
    }
  }
  return stack.empty();
}

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + what.size())) ++n;
  return n;
}

std::vector<hsize_t> dataset_shape(const fs::path& file, const std::string& path) {
  H5::H5File h5(file.string(), H5F_ACC_RDONLY);
  H5::DataSpace space = h5.openDataSet(path).getSpace();
  std::vector<hsize_t> dims(static_cast<std::size_t>(space.getSimpleExtentNdims()));
  space.getSimpleExtentDims(dims.data());
  return dims;
}

std::vector<double> dataset_values(const fs::path& file, const std::string& path) {
  H5::H5File h5(file.string(), H5F_ACC_RDONLY);
  H5::DataSet ds = h5.openDataSet(path);
  std::vector<double> v(static_cast<std::size_t>(ds.getSpace().getSimpleExtentNpoints()));
  ds.read(v.data(), H5::PredType::NATIVE_DOUBLE);
  return v;
}

std::string string_attribute(const H5::H5Object& obj, const std::string& name) {
  H5::Attribute a = obj.openAttribute(name);
  std::string s;
  a.read(a.getStrType(), s);
  return s;
}

bool tool_available(const std::string& tool) {
  return std::system(("command -v " + tool + " >/dev/null 2>&1").c_str()) == 0;
}

// ---------------------------------------------------------------------------------------------
// Run directory

TEST_F(IoRunDirectory, AtomicWritesLeaveNoTemporaryAndRightContent) {
  const auto run = RunDirectory::create(dir_ / "run", false);
  const nlohmann::json j = {{"case", "breathing"}, {"re", 0.1}, {"list", {1, 2, 3}}};
  run.write_json("case.json", j);
  run.write_text("notes.txt", "line one\nline two\n");
  run.write_text("notes.txt", "replaced\n");
  EXPECT_EQ(nlohmann::json::parse(read_text(run.path("case.json"))), j);
  EXPECT_EQ(read_text(run.path("notes.txt")), "replaced\n");
  EXPECT_TRUE(leftovers(run.root()).empty());
  EXPECT_THROW(run.write_text("../escape.txt", "x"), core::Error);
  EXPECT_THROW(run.write_text("sub/dir.txt", "x"), core::Error);
}

TEST_F(IoRunDirectory, ManifestIsRunningUntilFinished) {
  auto run = RunDirectory::create(dir_ / "run", false);
  EXPECT_EQ(RunDirectory::run_status(run.root()), "incomplete");
  run.update_manifest({{"environment", environment_json(2)}});
  EXPECT_EQ(RunDirectory::run_status(run.root()), "incomplete");
  EXPECT_THROW(run.update_manifest({{"status", "ok"}}), core::Error);
  EXPECT_THROW(run.finish("great"), core::Error);
  run.finish("diverged", {{"steps", 1234}, {"wall_time_s", 1.5}});
  EXPECT_EQ(RunDirectory::run_status(run.root()), "diverged");
  const auto m = nlohmann::json::parse(read_text(run.path("manifest.json")));
  EXPECT_EQ(m["status"], "diverged");
  EXPECT_EQ(m["steps"], 1234);
  EXPECT_EQ(m["environment"]["threads"], 2);
  EXPECT_TRUE(m.contains("started_utc"));
  EXPECT_TRUE(m.contains("finished_utc"));
  EXPECT_THROW(run.finish("ok"), core::Error);  // only once
}

TEST_F(IoRunDirectory, RunStatusOfKilledAndForeignDirectories) {
  EXPECT_EQ(RunDirectory::run_status(dir_ / "does_not_exist"), "missing");
  EXPECT_EQ(RunDirectory::run_status(dir_), "missing");
  // A process killed mid-run leaves its manifest saying "running".
  std::ofstream(dir_ / "manifest.json") << R"({"status": "running"})";
  EXPECT_EQ(RunDirectory::run_status(dir_), "incomplete");
  std::ofstream(dir_ / "manifest.json") << R"({"steps": 10})";
  EXPECT_EQ(RunDirectory::run_status(dir_), "incomplete");
  std::ofstream(dir_ / "manifest.json") << R"({"status": "ok)";  // truncated
  EXPECT_EQ(RunDirectory::run_status(dir_), "incomplete");
  std::ofstream(dir_ / "manifest.json") << R"({"status": "ok"})";
  EXPECT_EQ(RunDirectory::run_status(dir_), "ok");
}

TEST_F(IoRunDirectory, RefusesToReplaceWhatIsNotARun) {
  const fs::path foreign = dir_ / "thesis";
  fs::create_directories(foreign);
  std::ofstream(foreign / "chapter1.tex") << "precious";
  try {
    RunDirectory::create(foreign, /*overwrite=*/true);
    FAIL() << "a directory that is not a caplab run must be refused";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(foreign.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("choose another output directory"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text(foreign / "chapter1.tex"), "precious");

  const fs::path file = dir_ / "a_file";
  std::ofstream(file) << "x";
  EXPECT_THROW(RunDirectory::create(file, true), core::InputError);

  // An empty directory is fine.
  fs::create_directories(dir_ / "empty");
  EXPECT_NO_THROW(RunDirectory::create(dir_ / "empty", false));
}

TEST_F(IoRunDirectory, ReplacesAPreviousRunOnlyWhenAsked) {
  const fs::path out = dir_ / "run";
  {
    auto run = RunDirectory::create(out, false);
    run.write_text("old.txt", "old");
    run.finish("ok");
  }
  try {
    RunDirectory::create(out, false);
    FAIL() << "an existing run must not be replaced without overwrite";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--overwrite"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(out / "old.txt"));
  const auto run = RunDirectory::create(out, true);
  EXPECT_FALSE(fs::exists(out / "old.txt"));
  EXPECT_EQ(RunDirectory::run_status(out), "incomplete");
}

TEST_F(IoRunDirectory, PartialFilesAreCommittedAndOkRequiresIt) {
  auto run = RunDirectory::create(dir_ / "run", false);
  {
    SeriesWriter series(run.partial_path("series.h5"), {{"t", "s", "time"}});
    series.append(std::vector<double>{0.0});
    series.close();
  }
  EXPECT_TRUE(fs::exists(run.root() / "series.h5.partial"));
  EXPECT_THROW(run.finish("ok"), core::Error);  // never committed
  EXPECT_FALSE(run.finished());
  run.commit_file("series.h5");
  EXPECT_TRUE(fs::exists(run.path("series.h5")));
  EXPECT_TRUE(leftovers(run.root()).empty());
  EXPECT_THROW(run.commit_file("series.h5"), core::Error);  // nothing left to commit
  run.finish("ok");
  EXPECT_EQ(RunDirectory::run_status(run.root()), "ok");
}

TEST(IoManifest, EnvironmentHasProvenance) {
  const auto env = environment_json(3);
  for (const char* key : {"version", "git_sha", "git_dirty", "compiler", "flags", "build_type"})
    EXPECT_TRUE(env["build"].contains(key)) << key;
  EXPECT_EQ(env["threads"], 3);
  EXPECT_FALSE(env["host"].get<std::string>().empty());
  EXPECT_FALSE(env["cpu_model"].get<std::string>().empty());
  const std::regex iso(R"(\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}Z)");
  EXPECT_TRUE(std::regex_match(env["date_utc"].get<std::string>(), iso)) << env["date_utc"];
  EXPECT_FALSE(std::regex_match(std::string("2024-01-01 10:00:00"), iso));  // the comparator can fail
}

// ---------------------------------------------------------------------------------------------
// Series

TEST_F(IoSeries, RoundTripIsExactWithAttributes) {
  const fs::path file = dir_ / "series.h5";
  const std::vector<SeriesColumn> columns = {{"t", "s", "physical time"},
                                             {"D", "1", "Taylor deformation (L - B) / (L + B)"},
                                             {"theta", "rad", "inclination of the long axis to the flow"}};
  {
    SeriesWriter series(file, columns, {{"case", "shear_capsule_2d"}, {"capillary", 0.05}},
                        /*flush_every=*/64);
    for (int i = 0; i < 1000; ++i) {
      const double t = 1e-3 * i;
      series.append(std::vector<double>{t, std::sin(t) / 3.0, 1.0 / (i + 1)});
      if (i == 500) {
        EXPECT_EQ(series.rows(), 501u);  // written and buffered rows
      }
    }
    EXPECT_THROW(series.append(std::vector<double>{1.0, 2.0}), core::Error);
    series.close();
    EXPECT_THROW(series.append(std::vector<double>{1.0, 2.0, 3.0}), core::Error);
  }
  const auto s = read_series(file);
  ASSERT_EQ(s.size(), 3u);
  ASSERT_EQ(s.at("t").size(), 1000u);
  for (int i = 0; i < 1000; ++i) {
    const double t = 1e-3 * i;
    EXPECT_EQ(s.at("t")[i], t);
    EXPECT_EQ(s.at("D")[i], std::sin(t) / 3.0);
    EXPECT_EQ(s.at("theta")[i], 1.0 / (i + 1));
  }
  const auto read_columns = read_series_columns(file);
  ASSERT_EQ(read_columns.size(), 3u);
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_EQ(read_columns[c].name, columns[c].name);
    EXPECT_EQ(read_columns[c].unit, columns[c].unit);
    EXPECT_EQ(read_columns[c].definition, columns[c].definition);
  }

  // Attributes and layout through the HDF5 C++ API directly.
  H5::H5File h5(file.string(), H5F_ACC_RDONLY);
  EXPECT_EQ(string_attribute(h5, "case"), "shear_capsule_2d");
  EXPECT_EQ(string_attribute(h5, "capillary"), "0.05");
  H5::DataSet d = h5.openDataSet("D");
  EXPECT_EQ(string_attribute(d, "unit"), "1");
  EXPECT_EQ(string_attribute(d, "definition"), "Taylor deformation (L - B) / (L + B)");
  H5::DataSpace space = d.getSpace();
  ASSERT_EQ(space.getSimpleExtentNdims(), 1);
  hsize_t dims = 0, max_dims = 0;
  space.getSimpleExtentDims(&dims, &max_dims);
  EXPECT_EQ(dims, 1000u);
  EXPECT_EQ(max_dims, H5S_UNLIMITED);
  EXPECT_EQ(d.getCreatePlist().getLayout(), H5D_CHUNKED);
}

TEST_F(IoSeries, RejectsBadColumns) {
  EXPECT_THROW(SeriesWriter(dir_ / "a.h5", {{"t", "s", ""}, {"t", "s", ""}}), core::Error);
  EXPECT_THROW(SeriesWriter(dir_ / "b.h5", {{"E/E0", "1", ""}}), core::Error);
  EXPECT_THROW(SeriesWriter(dir_ / "c.h5", {}), core::Error);
  EXPECT_THROW(SeriesWriter(dir_ / "d.h5", {{"t", "s", ""}}, {{"columns", "x"}}), core::Error);
  EXPECT_THROW(read_series(dir_ / "missing.h5"), core::InputError);
}

// ---------------------------------------------------------------------------------------------
// Snapshots

TEST(IoXmlCheck, RejectsUnbalancedTags) {
  EXPECT_TRUE(tags_balanced("<?xml?><a x=\"1\"><b/><c></c></a>"));
  EXPECT_FALSE(tags_balanced("<a><b></a></b>"));
  EXPECT_FALSE(tags_balanced("<a><b>"));
}

TEST_F(IoSnapshot, Layout3DIsXFastestAndXdmfOrderIsZYX) {
  const field::Grid<3> grid({4, 3, 2}, Vec<3>(0.5, -1.0, 2.0), 0.25);
  const auto value = [](int i, int j, int k) { return i + 10.0 * j + 100.0 * k; };
  // Interior-only layout for rho, ghost-inclusive layout for the velocity components.
  std::vector<double> rho;
  field::for_each_interior(grid, [&](const Index<3>& ijk) { rho.push_back(value(ijk[0], ijk[1], ijk[2])); });
  std::array<std::vector<double>, 3> u;
  for (auto& c : u) c.assign(static_cast<std::size_t>(grid.size()), -99.0);  // ghosts must not appear
  field::for_each_interior(grid, [&](const Index<3>& ijk) {
    for (int a = 0; a < 3; ++a) u[a][grid.index(ijk)] = (a + 1) * value(ijk[0], ijk[1], ijk[2]);
  });

  const fs::path h5 = dir_ / "snapshots.h5", xdmf = dir_ / "snapshots.xdmf";
  SnapshotWriter<3> writer(h5, xdmf, "", {{"case", "sphere"}});
  writer.add_grid_field_step(0.0, grid, "fine", {{"rho", rho}}, {{"u", {u[0], u[1], u[2]}}});
  const field::Grid<3> coarse({2, 2, 2}, Vec<3>(0.0, 0.0, 0.0), 1.0);
  const std::vector<double> ones(8, 1.0);
  writer.add_grid_field_step(0.0, coarse, "coarse", {{"rho", ones}});
  // A sphere-ish triangle mesh.
  const std::vector<Vec<3>> points = {Vec<3>(1, 0, 0), Vec<3>(0, 1, 0), Vec<3>(0, 0, 1), Vec<3>(-1, 0, 0)};
  const std::vector<std::array<int, 3>> triangles = {{0, 1, 2}, {1, 3, 2}};
  const std::vector<double> tension = {1, 2, 3, 4};
  const std::vector<Vec<3>> force(4, Vec<3>(0.1, 0.2, 0.3));
  writer.add_mesh_step(0.0, "capsule", points, triangles, {{"tension", tension}}, {{"force", force}});
  writer.add_grid_field_step(0.5, grid, "fine", {{"rho", rho}});
  EXPECT_EQ(writer.steps(), 2u);
  EXPECT_TRUE(leftovers(dir_).empty());

  // Rejected calls leave no trace.
  EXPECT_THROW(writer.add_grid_field_step(0.25, grid, "fine", {{"rho", rho}}),
               core::Error);                                                                 // time goes back
  EXPECT_THROW(writer.add_grid_field_step(0.5, grid, "fine", {{"rho", rho}}), core::Error);  // twice
  EXPECT_THROW(writer.add_grid_field_step(0.7, grid, "fine", {{"rho", ones}}), core::Error);  // wrong size
  EXPECT_THROW(writer.add_mesh_step(0.7, "capsule", points, std::vector<std::array<int, 3>>{{0, 1, 4}}),
               core::Error);  // node out of range
  EXPECT_EQ(writer.steps(), 2u);
  writer.close();
  EXPECT_THROW(writer.add_grid_field_step(1.0, grid, "fine", {{"rho", rho}}), core::Error);

  const std::string xml = read_text(xdmf);
  EXPECT_TRUE(tags_balanced(xml)) << xml;
  EXPECT_NE(xml.find(R"(TopologyType="3DCoRectMesh" Dimensions="2 3 4")"), std::string::npos) << xml;
  EXPECT_NE(xml.find(R"(Format="XML">2 -1 0.5</DataItem>)"), std::string::npos) << xml;  // origin z y x
  EXPECT_NE(xml.find(R"(<DataItem Dimensions="2 3 4 3" NumberType="Float" Precision="8" Format="HDF">)"
                     "snapshots.h5:/step_000000/fine/u<"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find(R"(TopologyType="Triangle" NumberOfElements="2")"), std::string::npos) << xml;
  EXPECT_EQ(count(xml, R"(CollectionType="Temporal")"), 1);
  EXPECT_EQ(count(xml, R"(CollectionType="Spatial")"), 2);
  EXPECT_EQ(count(xml, R"(<Time Value="0"/>)"), 1);
  EXPECT_EQ(count(xml, R"(<Time Value="0.5"/>)"), 1);
  EXPECT_EQ(count(xml, R"(GridType="Uniform")"), 4);

  EXPECT_EQ(dataset_shape(h5, "/step_000000/fine/rho"), (std::vector<hsize_t>{2, 3, 4}));
  EXPECT_EQ(dataset_shape(h5, "/step_000000/fine/u"), (std::vector<hsize_t>{2, 3, 4, 3}));
  EXPECT_EQ(dataset_shape(h5, "/step_000000/capsule/points"), (std::vector<hsize_t>{4, 3}));
  EXPECT_EQ(dataset_shape(h5, "/step_000000/capsule/connectivity"), (std::vector<hsize_t>{2, 3}));
  const auto rho_read = dataset_values(h5, "/step_000001/fine/rho");
  const auto u_read = dataset_values(h5, "/step_000000/fine/u");
  const int i = 3, j = 1, k = 1, nx = 4, ny = 3;
  const std::size_t at = static_cast<std::size_t>((k * ny + j) * nx + i);
  EXPECT_EQ(rho_read[at], value(i, j, k));
  EXPECT_EQ(u_read[3 * at + 0], 1 * value(i, j, k));
  EXPECT_EQ(u_read[3 * at + 2], 3 * value(i, j, k));
  for (double v : u_read) EXPECT_NE(v, -99.0);
  EXPECT_EQ(dataset_values(h5, "/step_000000/capsule/force")[5], 0.3);

  H5::H5File file(h5.string(), H5F_ACC_RDONLY);
  EXPECT_EQ(string_attribute(file, "case"), "sphere");
  double t = -1.0;
  file.openGroup("step_000001").openAttribute("time").read(H5::PredType::NATIVE_DOUBLE, &t);
  EXPECT_EQ(t, 0.5);

  if (tool_available("xmllint")) {
    EXPECT_EQ(std::system(("xmllint --noout " + xdmf.string()).c_str()), 0);
  }
  if (tool_available("h5dump")) {
    const fs::path dump = dir_ / "dump.txt";
    ASSERT_EQ(std::system(("h5dump -H " + h5.string() + " > " + dump.string()).c_str()), 0);
    const std::string header = read_text(dump);
    EXPECT_NE(header.find("DATASET \"rho\""), std::string::npos);
    EXPECT_NE(header.find("( 2, 3, 4 )"), std::string::npos) << header;
    EXPECT_NE(header.find("( 2, 3, 4, 3 )"), std::string::npos) << header;
  }
}

TEST_F(IoSnapshot, Layout2DIsOneLayerInZWithPaddedVectors) {
  const field::Grid<2> grid({4, 3}, Vec<2>(0.5, -1.0), 0.25);
  std::vector<double> vort;
  std::array<std::vector<double>, 2> u;
  field::for_each_interior(grid, [&](const Index<2>& ij) {
    vort.push_back(ij[0] + 10.0 * ij[1]);
    u[0].push_back(ij[0]);
    u[1].push_back(ij[1]);
  });
  const int n = 16;
  std::vector<Vec<2>> ring;
  for (int p = 0; p < n; ++p) ring.emplace_back(std::cos(2 * M_PI * p / n), std::sin(2 * M_PI * p / n));
  const auto segments = closed_ring_segments(n);
  EXPECT_EQ(segments.back(), (std::array<int, 2>{n - 1, 0}));

  const fs::path h5 = dir_ / "snapshots.h5.partial", xdmf = dir_ / "snapshots.xdmf";
  {
    SnapshotWriter<2> writer(h5, xdmf, "snapshots.h5");
    writer.add_grid_field_step(1.0, grid, "fine", {{"vorticity", vort}}, {{"u", {u[0], u[1]}}});
    writer.add_mesh_step(1.0, "capsule", ring, segments, {}, {{"velocity", ring}});
    // The index is valid after every addition.
    EXPECT_TRUE(tags_balanced(read_text(xdmf)));
  }
  const std::string xml = read_text(xdmf);
  EXPECT_TRUE(tags_balanced(xml)) << xml;
  EXPECT_NE(xml.find(R"(TopologyType="3DCoRectMesh" Dimensions="1 3 4")"), std::string::npos) << xml;
  EXPECT_EQ(xml.find("2DCoRectMesh"), std::string::npos);
  EXPECT_NE(xml.find(R"(Format="XML">0 -1 0.5</DataItem>)"), std::string::npos) << xml;
  EXPECT_NE(xml.find(R"(Dimensions="3 4" NumberType="Float" Precision="8" Format="HDF">snapshots.h5:)"
                     "/step_000000/fine/vorticity<"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find(R"(TopologyType="Polyline" NodesPerElement="2" NumberOfElements="16")"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find(R"(<Geometry GeometryType="XYZ">)"), std::string::npos);

  EXPECT_EQ(dataset_shape(h5, "/step_000000/fine/vorticity"), (std::vector<hsize_t>{3, 4}));
  EXPECT_EQ(dataset_shape(h5, "/step_000000/fine/u"), (std::vector<hsize_t>{3, 4, 3}));
  const auto w = dataset_values(h5, "/step_000000/fine/vorticity");
  const auto uu = dataset_values(h5, "/step_000000/fine/u");
  const int i = 2, j = 1, nx = 4;
  EXPECT_EQ(w[j * nx + i], 12.0);
  EXPECT_EQ(uu[3 * (j * nx + i) + 0], 2.0);
  EXPECT_EQ(uu[3 * (j * nx + i) + 1], 1.0);
  EXPECT_EQ(uu[3 * (j * nx + i) + 2], 0.0);
  const auto pts = dataset_values(h5, "/step_000000/capsule/points");
  ASSERT_EQ(pts.size(), 3u * n);
  EXPECT_EQ(pts[3 * 4 + 1], ring[4][1]);
  EXPECT_EQ(pts[3 * 4 + 2], 0.0);
  if (tool_available("xmllint")) {
    EXPECT_EQ(std::system(("xmllint --noout " + xdmf.string()).c_str()), 0);
  }
}


// ---------------------------------------------------------------- checkpoints and resuming

class IoCheckpoint : public IoTest {};

/// A class with state, as the solver's classes write it: one function saves and restores.
struct State {
  std::vector<double> grows;
  std::array<float, 3> fixed{};
  std::int32_t counter = 0;
  long step = 0;
  bool flag = false;
  std::string text;
  template <class Archive>
  void checkpoint(Archive& ar) {
    ar("a/grows", grows);
    ar("a/b/fixed", std::span<float>(fixed));
    ar("counter", counter);
    ar("step", step);
    ar("flag", flag);
    ar("text", text);
  }
};

TEST_F(IoCheckpoint, RoundTripIsExact) {
  State s{{1.0 / 3.0, -0.0, 1e-300}, {1.5f, 2.5f, 1e-30f}, -7, 123456789012L, true, "{\"x\": 1}"};
  {
    CheckpointWriter w(dir_ / "c.h5");
    s.checkpoint(w);
    w.close();
    EXPECT_GT(w.file_bytes(), 0u);
  }
  State r;
  CheckpointReader in(dir_ / "c.h5");
  r.checkpoint(in);
  EXPECT_EQ(r.grows, s.grows);
  EXPECT_EQ(r.fixed, s.fixed);
  EXPECT_EQ(r.counter, -7);
  EXPECT_EQ(r.step, 123456789012L);
  EXPECT_TRUE(r.flag);
  EXPECT_EQ(r.text, s.text);
  EXPECT_TRUE(in.contains("a/b/fixed"));
  EXPECT_FALSE(in.contains("a/c/fixed"));
  EXPECT_FALSE(in.contains("nothing"));
}

TEST_F(IoCheckpoint, ReaderRefusesMissingEntriesAndOtherSizesOrTypes) {
  {
    CheckpointWriter w(dir_ / "c.h5");
    std::vector<double> v{1, 2, 3};
    w("v", v);
  }
  CheckpointReader in(dir_ / "c.h5");
  std::array<double, 2> two{};
  EXPECT_THROW(in("v", std::span<double>(two)), core::Error);
  std::vector<float> other;
  EXPECT_THROW(in("v", other), core::Error);
  double missing = 0;
  try {
    in("w", missing);
    FAIL() << "a missing entry must be refused";
  } catch (const core::Error& e) {
    EXPECT_NE(std::string(e.what()).find("'w'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CheckpointReader(dir_ / "absent.h5"), core::Error);
}

TEST_F(IoSnapshot, ReopenDropsTheStepsAfterTheIndexAndContinues) {
  const fs::path h5 = dir_ / "snapshots.h5.partial", xdmf = dir_ / "snapshots.xdmf";
  const int n = 8;
  std::vector<Vec<2>> ring;
  for (int p = 0; p < n; ++p) ring.emplace_back(std::cos(2 * M_PI * p / n), std::sin(2 * M_PI * p / n));
  const auto segments = closed_ring_segments(n);
  nlohmann::json index;
  {
    SnapshotWriter<2> w(h5, xdmf, "snapshots.h5");
    w.add_mesh_step(0.0, "capsule", ring, segments);
    w.add_mesh_step(1.0, "capsule", ring, segments);
    index = w.index();  // the checkpoint is taken here
    w.add_mesh_step(2.0, "capsule", ring, segments);  // written by the process that is then killed
  }
  {
    auto w = SnapshotWriter<2>::reopen(h5, xdmf, "snapshots.h5", index);
    EXPECT_EQ(w.steps(), 2u);
    w.add_mesh_step(2.0, "capsule", ring, segments);
    w.add_mesh_step(3.0, "capsule", ring, segments);
    EXPECT_EQ(w.steps(), 4u);
  }
  const std::string xml = read_text(xdmf);
  EXPECT_TRUE(tags_balanced(xml));
  EXPECT_NE(xml.find("step_000003"), std::string::npos);
  H5::H5File f(h5.string(), H5F_ACC_RDONLY);
  EXPECT_EQ(f.getNumObjs(), 4u);
  EXPECT_THROW(SnapshotWriter<2>::reopen(dir_ / "absent.h5", xdmf, "snapshots.h5", index), core::Error);
}

TEST_F(IoRunDirectory, ResumeTakesOnlyAnInterruptedRunWithACheckpoint) {
  auto expect_refused = [](const fs::path& d, const std::string& why) {
    try {
      RunDirectory::resume(d);
      FAIL() << "resume of " << d << " must be refused";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  expect_refused(dir_ / "nothing", "not a caplab run directory");
  {
    auto run = RunDirectory::create(dir_ / "killed", false);  // status "running": killed
  }
  expect_refused(dir_ / "killed", "before it wrote a checkpoint");
  write_file_atomically(dir_ / "killed" / "checkpoint.h5", "x");
  {
    auto run = RunDirectory::resume(dir_ / "killed");
    EXPECT_EQ(run.manifest()["status"], "running");
    EXPECT_EQ(run.manifest()["resumed"].size(), 1u);
    run.finish("ok");
  }
  expect_refused(dir_ / "killed", "finished ok");
  for (const char* status : {"diverged", "input_error"}) {
    {
      auto run = RunDirectory::create(dir_ / status, false);
      write_file_atomically(dir_ / status / "checkpoint.h5", "x");
      run.finish(status);
    }
    expect_refused(dir_ / status, status == std::string("diverged") ? "diverge again" : "fix the case");
  }
}

TEST_F(IoRunDirectory, ARunHeldByItsWriterIsRefusedToOthers) {
  {
    auto run = RunDirectory::create(dir_ / "live", false);
    EXPECT_TRUE(RunDirectory::is_running(run.root()));
    write_file_atomically(dir_ / "live" / "checkpoint.h5", "x");
    for (int attempt = 0; attempt < 2; ++attempt) {
      try {
        if (attempt == 0) RunDirectory::resume(dir_ / "live");
        if (attempt == 1) RunDirectory::create(dir_ / "live", true);
        FAIL() << "a second writer must be refused";
      } catch (const core::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("another process"), std::string::npos) << e.what();
      }
    }
    auto moved = std::move(run);  // the lock goes with the object
    EXPECT_TRUE(RunDirectory::is_running(dir_ / "live"));
  }
  EXPECT_FALSE(RunDirectory::is_running(dir_ / "live"));  // killed: resumable
  EXPECT_FALSE(RunDirectory::is_running(dir_ / "does_not_exist"));
  auto resumed = RunDirectory::resume(dir_ / "live");
  EXPECT_EQ(resumed.manifest()["resumed"].size(), 1u);
}

TEST_F(IoRunDirectory, CompareRunsFindsEveryDifference) {
  auto make = [&](const std::string& name, double x, const std::string& mode) {
    const fs::path d = dir_ / name;
    fs::create_directories(d);
    {
      SeriesWriter s(d / "series.h5", {{"t", "L/U", "time"}, {"x", "1", "value"}});
      for (int k = 0; k < 3; ++k) s.append(std::vector<double>{double(k), k == 2 ? x : 1.0});
      s.close();
    }
    write_file_atomically(d / "summary.json", nlohmann::json{{"metrics", {{"x", {{"value", x}}}, {"mode", mode}}}}.dump());
    return d;
  };
  const auto a = make("a", 1.0, "steady"), b = make("b", 1.0, "steady"), c = make("c", 1.0 + 1e-14, "steady"),
             d = make("d", 1.0, "tumbling");
  EXPECT_TRUE(compare_runs(a, b).identical());
  const auto ac = compare_runs(a, c);
  EXPECT_FALSE(ac.identical());
  EXPECT_EQ(ac.differing, 2u);  // the series value and the summary value
  EXPECT_NEAR(ac.max_relative, 1e-14, 1e-15);
  EXPECT_TRUE(compare_runs(a, c, 1e-12).problems.empty());
  EXPECT_FALSE(compare_runs(a, d, 1.0).problems.empty());  // strings compare exactly
}

}  // namespace
}  // namespace caplab::io
