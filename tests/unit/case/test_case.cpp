// Case loading: the canonical cylinder case at every fidelity level, `--set` overrides, the
// resolved JSON, catalogue/schema.json against the loader's own description of the format,
// and one rejection per kind of bad input — each asserting the JSON path of the error and the
// words that tell the user what to fix.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "case/case_schema.hpp"
#include "case/load_case.hpp"
#include "core/error.hpp"

namespace caplab::cases {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// Suites are named case_* so that `ctest -R case` selects them.
const fs::path source_dir{CAPLAB_SOURCE_DIR};
const fs::path cylinder_file = source_dir / "catalogue/ch2/cylinder_re100.json";


/// Runs `f`, expects a core::InputError at JSON path `path` whose message contains `path` (when
/// not empty) and every one of `words`.
void expect_rejected(const std::function<void()>& f, const std::string& path,
                     const std::vector<std::string>& words) {
  try {
    f();
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.json_path(), path) << what;
    if (!path.empty()) {
      EXPECT_NE(what.find(path), std::string::npos) << "no path " << path << " in: " << what;
    }
    for (const auto& w : words)
      EXPECT_NE(what.find(w), std::string::npos) << "no \"" << w << "\" in: " << what;
    if (std::getenv("CAPLAB_PRINT_ERRORS")) std::printf("%s\n", what.c_str());
    return;
  }
  ADD_FAILURE() << "accepted, but should be rejected at " << path;
}

void expect_set_rejected(const std::vector<std::string>& overrides, const std::string& path,
                         const std::vector<std::string>& words) {
  expect_rejected([&] { load_case(cylinder_file, "standard", overrides); }, path, words);
}

void expect_doc_rejected(const json& doc, const std::string& path, const std::vector<std::string>& words) {
  expect_rejected([&] { parse_case(doc, "edited.json", "standard", {}); }, path, words);
}

json cylinder_json() { return read_case_json(cylinder_file); }

// A temporary file with the given text, removed at the end of the test.
class TempFile {
 public:
  explicit TempFile(const std::string& text)
      : path_(fs::temp_directory_path() /
              ("caplab_case_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
               ".json")) {
    std::ofstream(path_) << text;
  }
  ~TempFile() { fs::remove(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// ---------------------------------------------------------------- the canonical case

void expect_cylinder_common(const CaseSpec& spec) {
  EXPECT_EQ(spec.id, "ch2/cylinder_re100");
  EXPECT_EQ(spec.source_file, cylinder_file.string());
  const PhysicsSpec& p = spec.physics;
  EXPECT_EQ(p.dimension, 2);
  EXPECT_EQ(p.flow.type, FlowSpec::Type::uniform);
  EXPECT_EQ(p.flow.direction, (std::vector<double>{1, 0}));
  EXPECT_DOUBLE_EQ(p.reynolds, 100);
  EXPECT_EQ(p.domain_size, (std::vector<double>{30, 20}));
  EXPECT_EQ(p.boundaries, (std::vector<BoundaryType>{BoundaryType::far_field, BoundaryType::far_field}));
  ASSERT_EQ(p.bodies.size(), 1u);
  EXPECT_EQ(p.bodies[0].name, "cylinder");
  EXPECT_EQ(p.bodies[0].shape.type, ShapeSpec::Type::circle);
  EXPECT_EQ(p.bodies[0].shape.center, (std::vector<double>{10, 10}));
  EXPECT_DOUBLE_EQ(p.bodies[0].shape.diameter, 1);
  ASSERT_TRUE(p.bodies[0].motion.has_value());
  EXPECT_EQ(p.bodies[0].motion->type, RigidMotionSpec::Type::fixed);

  const NumericsSpec& n = spec.numerics;
  EXPECT_EQ(n.grid.refinement, GridSpec::Refinement::two_level);
  EXPECT_EQ(n.grid.fine_min, (std::vector<double>{8, 8}));
  EXPECT_EQ(n.grid.fine_max, (std::vector<double>{16, 12}));
  EXPECT_EQ(n.precision, Precision::double_);
  EXPECT_EQ(n.ib.kernel, IbSpec::Kernel::cosine4);
  EXPECT_DOUBLE_EQ(n.ib.marker_spacing, 0.79);
  EXPECT_EQ(n.ib.forcing_iterations, 1);
  EXPECT_EQ(n.threads, 0);

  EXPECT_DOUBLE_EQ(spec.outputs.series.interval, 0.1);
  EXPECT_EQ(spec.outputs.series.quantities,
            (std::vector<std::string>{"drag_coefficient", "lift_coefficient"}));
  EXPECT_EQ(spec.outputs.snapshots.fields, (std::vector<std::string>{"vorticity"}));
  ASSERT_EQ(spec.acceptance.size(), 3u);
  const AcceptanceSpec& a = spec.acceptance[0];
  EXPECT_EQ(a.metric, "drag_coefficient_mean");
  EXPECT_DOUBLE_EQ(a.reference_value, 1.438);
  EXPECT_EQ(a.comparison, "relative");
  EXPECT_EQ(a.tolerance,
            (std::map<std::string, double>{{"quick", 0.06}, {"standard", 0.02}, {"thesis", 0.02}}));
  EXPECT_FALSE(a.justification.empty());
}

TEST(case_cylinder, LoadsAtStandardAndThesis) {
  for (const std::string level : {"standard", "thesis"}) {
    SCOPED_TRACE(level);
    const CaseSpec spec = load_case(cylinder_file, level);
    expect_cylinder_common(spec);
    EXPECT_EQ(spec.fidelity, level);
    EXPECT_DOUBLE_EQ(spec.numerics.grid.fine_spacing, 0.02);
    EXPECT_DOUBLE_EQ(spec.numerics.end_time, 250);
    EXPECT_EQ(spec.outputs.snapshots.times, (std::vector<double>{250}));
    EXPECT_DOUBLE_EQ(spec.outputs.average_from, 150);
  }
  // Both levels run the thesis's numerics (2.2.1): U = 0.1, BGK and the equilibrium far field.
  for (const std::string level : {"standard", "thesis"}) {
    const CaseSpec spec = load_case(cylinder_file, level);
    EXPECT_EQ(spec.numerics.collision.op, CollisionSpec::Operator::bgk) << level;
    EXPECT_DOUBLE_EQ(spec.numerics.lattice_velocity, 0.1) << level;
    EXPECT_EQ(spec.numerics.far_field, FarFieldScheme::equilibrium) << level;
  }
}

TEST(case_cylinder, QuickLevelShortensTheRun) {
  const CaseSpec spec = load_case(cylinder_file, "quick");
  expect_cylinder_common(spec);
  EXPECT_EQ(spec.fidelity, "quick");
  EXPECT_DOUBLE_EQ(spec.numerics.grid.fine_spacing, 0.02);
  EXPECT_DOUBLE_EQ(spec.numerics.end_time, 120);
  EXPECT_DOUBLE_EQ(spec.resolved["numerics"]["end_time"].get<double>(), 120);
}

TEST(case_cylinder, ListsItsFidelityLevels) {
  EXPECT_EQ(fidelity_levels(cylinder_file), (std::vector<std::string>{"quick", "standard", "thesis"}));
}

TEST(case_cylinder, DefaultLevelIsStandard) { EXPECT_EQ(load_case(cylinder_file).fidelity, "standard"); }

// Every catalogue case must load at every level it defines.
TEST(case_catalogue, EveryCaseLoadsAtEveryLevel) {
  for (const auto& entry : fs::recursive_directory_iterator(source_dir / "catalogue")) {
    if (entry.path().extension() != ".json" || entry.path().filename() == "schema.json") continue;
    for (const auto& level : fidelity_levels(entry.path())) {
      SCOPED_TRACE(entry.path().string() + " at " + level);
      EXPECT_NO_THROW(load_case(entry.path(), level));
    }
  }
}

// The chapter 5 and 6 cases are written by Python generators (scripts/generate-ch*-cases): a
// string that lost its f prefix leaves "{name}" in the text a user reads.
TEST(case_catalogue, TitlesAndDescriptionsHaveNoUnfilledPlaceholders) {
  for (const auto& entry : fs::recursive_directory_iterator(source_dir / "catalogue")) {
    if (entry.path().extension() != ".json" || entry.path().filename() == "schema.json") continue;
    std::ifstream in(entry.path());
    const json doc = json::parse(in);
    for (const char* key : {"title", "description"}) {
      const std::string text = doc.value(key, std::string());
      EXPECT_EQ(text.find_first_of("{}"), std::string::npos) << entry.path() << " " << key << ": " << text;
    }
  }
}

// ---------------------------------------------------------------- overrides and resolved JSON

TEST(case_overrides, SetNumberStringAndArrayEntry) {
  const CaseSpec spec =
      load_case(cylinder_file, "standard",
                {"physics.reynolds=200", "numerics.ib.kernel=roma3", "physics.bodies.0.shape.center.1=10.5",
                 "outputs.series.quantities=[\"drag_coefficient\"]"});
  EXPECT_DOUBLE_EQ(spec.physics.reynolds, 200);
  EXPECT_EQ(spec.numerics.ib.kernel, IbSpec::Kernel::roma3);
  EXPECT_EQ(spec.physics.bodies[0].shape.center, (std::vector<double>{10, 10.5}));
  EXPECT_EQ(spec.outputs.series.quantities, (std::vector<std::string>{"drag_coefficient"}));
  EXPECT_EQ(spec.resolved["physics"]["reynolds"], 200);
  EXPECT_EQ(spec.resolved["numerics"]["ib"]["kernel"], "roma3");
}

TEST(case_overrides, ApplyAfterTheFidelityLevelAndInOrder) {
  const CaseSpec spec = load_case(
      cylinder_file, "quick", {"numerics.end_time=200", "numerics.end_time=180"});
  EXPECT_DOUBLE_EQ(spec.numerics.end_time, 180);
  EXPECT_DOUBLE_EQ(spec.outputs.average_from, 80);  // from the quick level
}

TEST(case_overrides, CreateOptionalKeysTheSchemaAllows) {
  json doc = cylinder_json();
  doc["numerics"].erase("ib");
  const CaseSpec spec = parse_case(doc, "edited.json", "standard",
                                   {"numerics.collision.operator=trt", "numerics.collision.magic=0.1875",
                                    "numerics.ib.forcing_iterations=3", "numerics.threads=4"});
  EXPECT_EQ(spec.numerics.collision.op, CollisionSpec::Operator::trt);
  EXPECT_DOUBLE_EQ(spec.numerics.collision.magic, 0.1875);
  EXPECT_EQ(spec.numerics.ib.forcing_iterations, 3);
  EXPECT_EQ(spec.numerics.ib.kernel, IbSpec::Kernel::cosine4);  // default kept
  EXPECT_EQ(spec.numerics.threads, 4);
}

TEST(case_resolved, RecordsDefaultsNormalisesAndReloadsToTheSameCase) {
  json doc = cylinder_json();
  doc["numerics"].erase("ib");
  doc["physics"]["flow"]["direction"] = {3, 4};
  const CaseSpec spec = parse_case(doc, "edited.json", "standard", {});
  EXPECT_NEAR(spec.physics.flow.direction[0], 0.6, 1e-15);
  EXPECT_NEAR(spec.physics.flow.direction[1], 0.8, 1e-15);
  EXPECT_EQ(spec.resolved["numerics"]["ib"],
            (json{{"kernel", "cosine4"}, {"marker_spacing", 0.79}, {"forcing_iterations", 1}}));
  EXPECT_EQ(spec.resolved["numerics"]["threads"], 0);
  const CaseSpec again = parse_case(spec.resolved, "case.json", "standard", {});
  EXPECT_EQ(again.resolved, spec.resolved);
}

TEST(case_resolved, UniformFlowDirectionDefaultsToPlusX) {
  json doc = cylinder_json();
  doc["physics"]["flow"].erase("direction");
  EXPECT_EQ(parse_case(doc, "edited.json", "standard", {}).physics.flow.direction,
            (std::vector<double>{1, 0}));
}

TEST(case_resolved, UniformRefinementNeedsNoFineRegion) {
  json doc = cylinder_json();
  doc["numerics"]["grid"] = {{"refinement", "uniform"}, {"fine_spacing", 0.05}};
  const CaseSpec spec = parse_case(doc, "edited.json", "standard", {});
  EXPECT_EQ(spec.numerics.grid.refinement, GridSpec::Refinement::uniform);
  EXPECT_TRUE(spec.numerics.grid.fine_min.empty());
}

// ---------------------------------------------------------------- rejected input: structure

TEST(case_rejects, UnknownKeyWithDidYouMean) {
  json doc = cylinder_json();
  doc["physics"]["reynold"] = doc["physics"]["reynolds"];
  doc["physics"].erase("reynolds");
  expect_doc_rejected(doc, "/physics/reynold",
                      {"edited.json", "unknown key \"reynold\"", "did you mean \"reynolds\"?"});
}

TEST(case_rejects, UnknownOverridePathWithDidYouMean) {
  expect_set_rejected({"numerics.grid.fine_spacng=0.04"}, "/numerics/grid/fine_spacng",
                      {"--set numerics.grid.fine_spacng=0.04", "did you mean \"fine_spacing\"?"});
  expect_set_rejected({"physics.reynolds.x=1"}, "/physics/reynolds/x", {"has no member \"x\""});
  expect_set_rejected({"physics.bodies.1.name=b"}, "/physics/bodies/1", {"index", "it has 1 entries"});
  json doc = cylinder_json();
  doc["outputs"].erase("snapshots");
  expect_rejected([&] { parse_case(doc, "edited.json", "standard", {"outputs.snapshots.times.0=1"}); },
                  "/outputs/snapshots/times/0", {"the array at /outputs/snapshots/times is empty or absent"});
  expect_set_rejected({"fidelity.quick=1"}, "/fidelity", {"levels are applied before overrides"});
  expect_set_rejected({"physics.reynolds"}, "", {"path=value"});
}

TEST(case_rejects, BadPathInAFidelityLevelThatIsNotApplied) {
  json doc = cylinder_json();
  doc["fidelity"]["thesis"]["numerics.grid.fine_spacing_"] = 0.02;
  expect_doc_rejected(doc, "/fidelity/thesis/numerics.grid.fine_spacing_",
                      {"\"fine_spacing_\" is not a key of /numerics/grid", "did you mean \"fine_spacing\"?"});
}

TEST(case_rejects, MissingRequiredKey) {
  json doc = cylinder_json();
  doc["physics"].erase("reynolds");
  expect_doc_rejected(doc, "/physics/reynolds",
                      {"required key \"reynolds\" is missing", "a finite number > 0"});
}

TEST(case_rejects, WrongType) {
  expect_set_rejected({"physics.reynolds=\"100\""}, "/physics/reynolds",
                      {"\"100\" (a string; write numbers without quotes)", "a finite number"});
  expect_set_rejected({"physics.dimension=2.5"}, "/physics/dimension",
                      {"2.5 (not an integer)", "an integer in [2, 3]"});
  expect_set_rejected({"physics.bodies={}"}, "/physics/bodies", {"(an object)", "an array"});
}

TEST(case_rejects, NanAndInfinity) {
  // "nan" is not JSON, so the override value is the string "nan".
  expect_set_rejected({"physics.reynolds=nan"}, "/physics/reynolds",
                      {"NaN and infinity are not allowed", "a finite number", "--set physics.reynolds=nan"});
  expect_set_rejected({"numerics.end_time=1e999"}, "/numerics/end_time",
                      {"NaN and infinity are not allowed"});
  json doc = cylinder_json();
  doc["physics"]["domain"]["size"][1] = std::nan("");
  expect_doc_rejected(doc, "/physics/domain/size/1", {"nan", "a finite number > 0"});
}

TEST(case_rejects, BadEnumerationListsTheAllowedValues) {
  expect_set_rejected({"numerics.collision.operator=mrt"}, "/numerics/collision/operator",
                      {"\"mrt\"", "one of \"bgk\", \"trt\""});
  expect_set_rejected({"physics.domain.boundaries.1=farfield"}, "/physics/domain/boundaries/1",
                      {"one of \"periodic\", \"far_field\", \"wall\"", "did you mean \"far_field\"?"});
}

TEST(case_rejects, UnknownFidelityLevelListsTheDefinedOnes) {
  expect_rejected([] { load_case(cylinder_file, "standrad"); }, "/fidelity",
                  {"\"standrad\"", "\"quick\", \"standard\", \"thesis\"", "did you mean \"standard\"?"});
}

TEST(case_rejects, VectorWithTheWrongNumberOfEntries) {
  expect_set_rejected({"physics.domain.size=[30, 20, 20]"}, "/physics/domain/size",
                      {"2 entries, one per axis", "physics.dimension is 2"});
}

// ---------------------------------------------------------------- rejected input: values

TEST(case_rejects, NegativeReynolds) {
  expect_set_rejected({"physics.reynolds=-5"}, "/physics/reynolds", {"-5", "a finite number > 0", "--set"});
}

TEST(case_rejects, OutOfRangeNumbers) {
  expect_set_rejected({"numerics.lattice_velocity=0.5"}, "/numerics/lattice_velocity",
                      {"0.5", "in (0, 0.4]"});
  expect_set_rejected({"numerics.ib.forcing_iterations=0"}, "/numerics/ib/forcing_iterations", {"in [1, 100]"});
  expect_set_rejected({"acceptance.0.tolerance.standard=0"}, "/acceptance/0/tolerance/standard", {"> 0"});
  expect_set_rejected({"acceptance.0.justification=\"\""}, "/acceptance/0/justification",
                      {"a non-empty string"});
}

TEST(case_rejects, ValueSetByAFidelityLevelNamesTheLevel) {
  json doc = cylinder_json();
  doc["fidelity"]["standard"]["numerics.end_time"] = -1;
  expect_doc_rejected(doc, "/numerics/end_time", {"-1 (set by fidelity level \"standard\")", "> 0"});
}

// ---------------------------------------------------------------- rejected input: consistency

TEST(case_rejects, SpacingThatDoesNotDivideTheDomain) {
  expect_set_rejected({"numerics.grid.fine_spacing=0.07"}, "/numerics/grid/fine_spacing",
                      {"along x (30)", "whole multiple of 2*fine_spacing",
                       "nearest valid fine_spacing for this axis "
                       "is 30/428"});
}

TEST(case_rejects, AbsurdNumberOfNodes) {
  expect_set_rejected({"numerics.grid.fine_spacing=0.0001"}, "/numerics/grid/fine_spacing",
                      {"at most 2e+09 lattice nodes"});
}

TEST(case_rejects, BodyOutsideTheFineRegion) {
  expect_set_rejected({"physics.bodies.0.shape.center=[15.8, 10]"}, "/physics/bodies/0/shape/center",
                      {"body \"cylinder\"", "inside the fine region", "3 fine spacings", "along x"});
}

TEST(case_rejects, BodyOutsideTheDomain) {
  expect_set_rejected({"physics.bodies.0.shape.center=[10, 19.8]"}, "/physics/bodies/0/shape/center",
                      {"body \"cylinder\"", "inside the domain", "along y"});
}

TEST(case_rejects, FineRegionOutsideTheDomainOrOffTheCoarseNodes) {
  expect_set_rejected({"numerics.grid.fine_region.max.0=32"}, "/numerics/grid/fine_region/max/0",
                      {"inside the domain [0, 30] along x", "4 coarse spacings"});
  expect_set_rejected({"numerics.grid.fine_region.min.1=0.08"}, "/numerics/grid/fine_region/min/1",
                      {"along y", "min >= 0.16"});
  expect_set_rejected({"numerics.grid.fine_region.min.0=8.01"}, "/numerics/grid/fine_region/min/0",
                      {"on a coarse node", "nearest is 8"});
  expect_set_rejected({"numerics.grid.fine_region.min=[16, 8]"}, "/numerics/grid/fine_region",
                      {"min < max", "along x"});
}

TEST(case_rejects, FineRegionPresenceMustMatchRefinement) {
  expect_set_rejected({"numerics.grid.refinement=uniform"}, "/numerics/grid/fine_region",
                      {"applies only when /numerics/grid/refinement is \"two_level\"", "\"uniform\" here"});
  json doc = cylinder_json();
  doc["numerics"]["grid"].erase("fine_region");
  expect_doc_rejected(doc, "/numerics/grid/fine_region",
                      {"missing", "required when /numerics/grid/refinement"});
}

TEST(case_rejects, MagicWithBgk) {
  expect_set_rejected({"numerics.collision.operator=bgk", "numerics.collision.magic=0.25"}, "/numerics/collision/magic",
                      {"applies only when /numerics/collision/operator is \"trt\"", "\"bgk\" here",
                       "set by --set numerics.collision.magic=0.25"});
}

TEST(case_overrides, BulkViscosityRatioWithEitherOperator) {
  for (const char* op : {"trt", "bgk"}) {
    const CaseSpec spec = load_case(cylinder_file, "quick",
                                    {std::string("numerics.collision.operator=") + op,
                                     "numerics.collision.bulk_viscosity_ratio=30"});
    ASSERT_TRUE(spec.numerics.collision.bulk_viscosity_ratio.has_value()) << op;
    EXPECT_DOUBLE_EQ(*spec.numerics.collision.bulk_viscosity_ratio, 30.0);
  }
  EXPECT_FALSE(load_case(cylinder_file, "quick", {}).numerics.collision.bulk_viscosity_ratio.has_value());
}

TEST(case_rejects, BulkViscosityRatioOutOfRange) {
  for (const char* value : {"0", "-2", "20000"})
    expect_set_rejected({std::string("numerics.collision.bulk_viscosity_ratio=") + value},
                        "/numerics/collision/bulk_viscosity_ratio", {"in (0, 10000]"});
}

TEST(case_rejects, DirectionForANonUniformFlowAndZeroDirection) {
  expect_set_rejected({"physics.flow.type=rest"}, "/physics/flow/direction",
                      {"applies only when", "\"uniform\""});
  expect_set_rejected({"physics.flow.direction=[0, 0]"}, "/physics/flow/direction", {"a non-zero vector"});
}

TEST(case_rejects, CircleIn3DAndSphereIn2D) {
  expect_set_rejected(
      {"physics.dimension=3", "physics.flow.direction=[1, 0, 0]", "physics.domain.size=[30, 20, 20]",
       "physics.domain.boundaries=[\"far_field\", \"far_field\", \"far_field\"]",
       "physics.bodies.0.shape.center=[10, 10, 10]", "numerics.grid.fine_region.min=[8, 8, 8]",
       "numerics.grid.fine_region.max=[16, 12, 12]"},
      "/physics/bodies/0/shape/type", {"\"circle\"", "3D shape for body \"cylinder\"", "\"sphere\""});
  expect_set_rejected({"physics.bodies.0.shape.type=sphere"}, "/physics/bodies/0/shape/type",
                      {"2D shape", "\"circle\""});
}

TEST(case_rejects, OutputTimesBeyondTheEnd) {
  expect_set_rejected({"outputs.snapshots.times=[100, 300]"}, "/outputs/snapshots/times/1",
                      {"300", "[0, 250]"});
  expect_set_rejected({"outputs.average_from=250"}, "/outputs/average_from",
                      {"[0, 250)", "must not be empty"});
}

TEST(case_rejects, PerformanceBudgetForAnUndefinedLevelOrWithoutReason) {
  json doc = cylinder_json();
  doc["performance"] = {{"wall_time_budget_s", {{"standard", 600}}}, {"justification", "issue 2"}};
  const auto spec = parse_case(doc, "edited.json", "quick", {});  // levels without a budget: not judged
  ASSERT_TRUE(spec.performance);
  EXPECT_EQ(spec.performance->wall_time_budget_s.at("standard"), 600);
  doc["performance"]["wall_time_budget_s"]["standrd"] = 600;
  expect_doc_rejected(doc, "/performance/wall_time_budget_s/standrd", {"did you mean \"standard\"?"});
  doc["performance"]["wall_time_budget_s"] = {{"standard", 0}};
  expect_doc_rejected(doc, "/performance/wall_time_budget_s/standard", {"0"});
  doc["performance"] = {{"wall_time_budget_s", {{"standard", 600}}}};
  expect_doc_rejected(doc, "/performance/justification", {});
}

TEST(case_rejects, ToleranceForAnUndefinedOrMissingLevel) {
  expect_set_rejected({"acceptance.0.tolerance.thesys=0.02"}, "/acceptance/0/tolerance/thesys",
                      {"did you mean \"thesis\"?"});
  json doc = cylinder_json();
  doc["acceptance"][0]["tolerance"].erase("thesis");
  expect_doc_rejected(doc, "/acceptance/0/tolerance", {"no tolerance for fidelity level \"thesis\""});
}

// ---------------------------------------------------------------- acceptance entries: mode

/// The cylinder case with a fourth acceptance entry comparing the flow regime (entry 3).
json with_mode_entry(const json& reference_mode) {
  json doc = cylinder_json();
  json entry = {{"metric", "mode"},
                {"reference", "references/capsule2d/claims.json#ch3.ellipse.G0.04.Eb0.06"},
                {"comparison", "mode"},
                {"justification", "thesis section 3.2.2 states the regime"}};
  if (!reference_mode.is_null()) entry["reference_mode"] = reference_mode;
  doc["acceptance"].push_back(entry);
  return doc;
}

TEST(case_acceptance, ModeEntryWithANameOrAnArrayLoads) {
  for (const json& modes : {json("tumbling"), json({"steady_tank_treading", "oscillating_tank_treading"})}) {
    SCOPED_TRACE(modes.dump());
    const CaseSpec spec = parse_case(with_mode_entry(modes), "edited.json", "standard", {});
    ASSERT_EQ(spec.acceptance.size(), 4u);
    const AcceptanceSpec& a = spec.acceptance[3];
    EXPECT_EQ(a.metric, "mode");
    EXPECT_EQ(a.comparison, "mode");
    EXPECT_TRUE(a.tolerance.empty());  // matched exactly: no tolerance per level
    EXPECT_EQ(a.reference_modes,
              modes.is_array() ? modes.get<std::vector<std::string>>() : std::vector<std::string>{modes});
    EXPECT_EQ(spec.resolved["acceptance"][3]["reference_mode"], modes);  // what the scorer reads
    EXPECT_FALSE(spec.resolved["acceptance"][3].contains("tolerance"));
  }
  // An override may change the regime like any other value.
  const CaseSpec set = parse_case(with_mode_entry("tumbling"), "edited.json", "standard",
                                  {"acceptance.3.reference_mode=steady_tank_treading"});
  EXPECT_EQ(set.resolved["acceptance"][3]["reference_mode"], "steady_tank_treading");
}

TEST(case_rejects, ModeEntryWithoutReferenceMode) {
  expect_doc_rejected(with_mode_entry(nullptr), "/acceptance/3/reference_mode",
                      {"required key \"reference_mode\" is missing", "\"tumbling\"", "non-empty array",
                       "required when /acceptance/3/comparison is \"mode\""});
}

TEST(case_rejects, ModeEntryWithANumericReferenceOrTolerance) {
  json doc = with_mode_entry("tumbling");
  doc["acceptance"][3]["tolerance"] = {{"quick", 0.1}, {"standard", 0.1}, {"thesis", 0.1}};
  expect_doc_rejected(doc, "/acceptance/3/tolerance",
                      {"no \"tolerance\" key", "matched exactly", "remove it"});
  doc = with_mode_entry("tumbling");
  doc["acceptance"][3]["reference_value"] = 1;
  expect_doc_rejected(doc, "/acceptance/3/reference_value", {"no \"reference_value\" key"});
}

TEST(case_rejects, MalformedOrUnknownReferenceMode) {
  expect_doc_rejected(with_mode_entry("tumbeling"), "/acceptance/3/reference_mode",
                      {"\"tumbeling\"", "did you mean \"tumbling\"?"});
  expect_doc_rejected(
      with_mode_entry({"tumbling", "swinging"}), "/acceptance/3/reference_mode/1",
      {"\"swinging\"", "\"steady_tank_treading\", \"oscillating_tank_treading\", \"tumbling\""});
  expect_doc_rejected(with_mode_entry(json::array()), "/acceptance/3/reference_mode", {"non-empty array"});
  expect_doc_rejected(with_mode_entry(2), "/acceptance/3/reference_mode", {"a mode name"});
  expect_doc_rejected(with_mode_entry({"tumbling", 2}), "/acceptance/3/reference_mode/1", {"a mode name"});
  expect_doc_rejected(with_mode_entry(""), "/acceptance/3/reference_mode",
                      {"one of \"steady_tank_treading\""});
}

TEST(case_rejects, NumericEntryNeedsValueAndToleranceAndNoReferenceMode) {
  json doc = cylinder_json();
  doc["acceptance"][0].erase("reference_value");
  expect_doc_rejected(doc, "/acceptance/0/reference_value",
                      {"required key \"reference_value\" is missing", "a finite number",
                       "required when /acceptance/0/comparison is \"relative\""});
  doc = cylinder_json();
  doc["acceptance"][0].erase("tolerance");
  expect_doc_rejected(doc, "/acceptance/0/tolerance", {"required key \"tolerance\" is missing"});
  doc = cylinder_json();
  doc["acceptance"][0]["reference_mode"] = "tumbling";
  expect_doc_rejected(doc, "/acceptance/0/reference_mode",
                      {"no \"reference_mode\" key", "belongs to the comparison \"mode\""});
  expect_set_rejected({"acceptance.0.comparison=modes"}, "/acceptance/0/comparison",
                      {"\"relative\", \"absolute\", \"time_series\", \"mode\"", "did you mean \"mode\"?"});
}

TEST(case_rejects, DuplicateBodyNames) {
  json doc = cylinder_json();
  json second = doc["physics"]["bodies"][0];
  second["shape"]["center"] = {13, 10};
  doc["physics"]["bodies"].push_back(second);
  expect_doc_rejected(doc, "/physics/bodies/1/name", {"\"cylinder\"", "not used by another body"});
}

// ---------------------------------------------------------------- rejected input: files

TEST(case_rejects, FileThatDoesNotExist) {
  expect_rejected([] { load_case(source_dir / "catalogue/no_such_case.json"); }, "",
                  {"no_such_case.json", "no such file"});
}

TEST(case_rejects, MalformedJsonWithLineAndColumn) {
  const TempFile file("{\n  \"id\": \"x\",\n  \"title\": ,\n}\n");
  expect_rejected([&] { load_case(file.path()); }, "",
                  {file.path().filename().string(), "malformed JSON", "line 3, column 12"});
}

TEST(case_rejects, KeyRepeatedInOneObject) {
  const TempFile file("{\"physics\": {\"bodies\": [{\"name\": \"a\"}, {\"name\": \"b\", \"name\": \"c\"}]}}");
  expect_rejected([&] { load_case(file.path()); }, "/physics/bodies/1/name",
                  {"the key \"name\" a second time", "at most once"});
}

// ---------------------------------------------------------------- catalogue/schema.json

json schema_json() {
  std::ifstream in(source_dir / "catalogue/schema.json");
  return json::parse(in);
}

// Follows "$ref": "#/$defs/..." within the schema document.
const json& resolve(const json& root, const json& node) {
  return node.contains("$ref") ? root.at(json::json_pointer(node.at("$ref").get<std::string>().substr(1)))
                               : node;
}

// The keys schema.json declares, in the form of schema_keys(): dotted path ("*" for array
// entries), whether the object requires it, and the enum of the value or of its entries.
std::set<std::tuple<std::string, bool, std::vector<std::string>>> published_keys(const json& root,
                                                                                 const json& node,
                                                                                 const std::string& path) {
  std::set<std::tuple<std::string, bool, std::vector<std::string>>> keys;
  const json& n = resolve(root, node);
  if (n.contains("items")) return published_keys(root, n.at("items"), path + ".*");
  if (!n.contains("properties")) return keys;
  const json required = n.value("required", json::array());
  for (const auto& [key, sub] : n.at("properties").items()) {
    const std::string p = path.empty() ? key : path + "." + key;
    const json& s = resolve(root, sub);
    const json& leaf = s.contains("items") ? resolve(root, s.at("items")) : s;
    keys.emplace(p, std::find(required.begin(), required.end(), key) != required.end(),
                 leaf.value("enum", std::vector<std::string>{}));
    keys.merge(published_keys(root, sub, p));
  }
  return keys;
}

std::set<std::tuple<std::string, bool, std::vector<std::string>>> loader_keys() {
  std::set<std::tuple<std::string, bool, std::vector<std::string>>> keys;
  for (const auto& k : schema_keys()) keys.emplace(k.path, k.required, k.choices);
  return keys;
}

TEST(case_schema, IsDraft202012AndDescribesEveryKey) {
  const json schema = schema_json();
  EXPECT_EQ(schema["$schema"], "https://json-schema.org/draft/2020-12/schema");
  std::function<void(const json&, const std::string&)> check = [&](const json& node,
                                                                   const std::string& where) {
    const json& n = resolve(schema, node);
    if (n.contains("items")) check(n["items"], where + "/items");
    if (!n.contains("properties")) return;
    for (const auto& [key, sub] : n["properties"].items()) {
      EXPECT_TRUE(sub.contains("description")) << where << "/" << key << " has no description";
      check(sub, where + "/" + key);
    }
  };
  check(schema, "");
}

TEST(case_schema, EveryKeyOfTheExampleIsInTheSchema) {
  const json schema = schema_json();
  std::function<void(const json&, const json&, const std::string&)> walk =
      [&](const json& value, const json& node, const std::string& where) {
        const json& n = resolve(schema, node);
        if (value.is_array() && n.contains("items"))
          for (const auto& v : value) walk(v, n["items"], where + "/*");
        if (!value.is_object() || !n.contains("properties")) return;  // free-key maps (fidelity, tolerance)
        for (const auto& [key, v] : value.items()) {
          ASSERT_TRUE(n["properties"].contains(key)) << where << "/" << key << " is not in schema.json";
          walk(v, n["properties"][key], where + "/" + key);
        }
      };
  walk(cylinder_json(), schema, "");
}

TEST(case_schema, PublishedSchemaAndLoaderAgreeOnKeysRequirementsAndEnums) {
  const auto published = published_keys(schema_json(), schema_json(), "");
  const auto loader = loader_keys();
  for (const auto& k : loader)
    EXPECT_TRUE(published.count(k)) << "schema.json lacks or differs on " << std::get<0>(k);
  for (const auto& k : published)
    EXPECT_TRUE(loader.count(k)) << "loader lacks or differs on " << std::get<0>(k);
  EXPECT_TRUE(loader.count({"physics.reynolds", true, {}}));  // the enumeration itself works
}

TEST(case_schema, ComparisonDetectsADifference) {
  json schema = schema_json();
  schema["properties"]["physics"]["properties"].erase("reynolds");
  EXPECT_NE(published_keys(schema, schema, ""), loader_keys());
  schema = schema_json();
  schema["properties"]["numerics"]["properties"]["collision"]["properties"]["operator"]["enum"].push_back(
      "mrt");
  EXPECT_NE(published_keys(schema, schema, ""), loader_keys());
}

TEST(case_schema, PublishedModesAreTheOnesTheLoaderAccepts) {
  const json schema = schema_json();
  const json& mode = schema["properties"]["acceptance"]["items"]["properties"]["reference_mode"];
  const std::vector<std::string> names = mode["anyOf"][0]["enum"].get<std::vector<std::string>>();
  EXPECT_EQ(names,
            (std::vector<std::string>{"steady_tank_treading", "oscillating_tank_treading", "tumbling"}));
  EXPECT_EQ(mode["anyOf"][1]["items"]["enum"], mode["anyOf"][0]["enum"]);
  for (const auto& name : names)
    EXPECT_NO_THROW(parse_case(with_mode_entry(name), "edited.json", "standard", {}));
  EXPECT_NO_THROW(parse_case(with_mode_entry(names), "edited.json", "standard", {}));
}

TEST(case_schema, DefaultsMatchTheSpecDefaults) {
  const json schema = schema_json();
  const json& numerics = schema["properties"]["numerics"]["properties"];
  const CaseSpec defaults;
  EXPECT_EQ(numerics["ib"]["properties"]["kernel"]["default"], "cosine4");
  EXPECT_EQ(defaults.numerics.ib.kernel, IbSpec::Kernel::cosine4);
  EXPECT_EQ(numerics["ib"]["properties"]["marker_spacing"]["default"], defaults.numerics.ib.marker_spacing);
  EXPECT_EQ(numerics["ib"]["properties"]["forcing_iterations"]["default"],
            defaults.numerics.ib.forcing_iterations);
  EXPECT_EQ(numerics["collision"]["properties"]["magic"]["default"], defaults.numerics.collision.magic);
  EXPECT_EQ(numerics["threads"]["default"], defaults.numerics.threads);
  EXPECT_EQ(schema["properties"]["outputs"]["properties"]["average_from"]["default"],
            defaults.outputs.average_from);
  EXPECT_EQ(schema["properties"]["outputs"]["properties"]["oscillation_threshold"]["default"],
            defaults.outputs.oscillation_threshold_deg);
}

// ---------------------------------------------------------------- capsules
const fs::path capsule_file = source_dir / "catalogue/ch3/ellipse_initial_G0.04_Eb0.4.json";
json capsule_json() { return read_case_json(capsule_file); }

TEST(case_capsule, OscillationThresholdIsReadAndRecordedInTheResolvedCase) {
  const CaseSpec spec = load_case(capsule_file, "standard", {"outputs.oscillation_threshold=0.25"});
  EXPECT_DOUBLE_EQ(spec.outputs.oscillation_threshold_deg, 0.25);
  EXPECT_EQ(spec.resolved["outputs"]["oscillation_threshold"], 0.25);
  EXPECT_DOUBLE_EQ(load_case(capsule_file, "standard").outputs.oscillation_threshold_deg, 1.0);
  expect_set_rejected({"outputs.oscillation_threshold=0"}, "/outputs/oscillation_threshold", {"(0, 45]"});
}

TEST(case_capsule, LoadsTheMembraneAndShapeWithDefaultsWritten) {
  const CaseSpec spec = load_case(capsule_file, "standard");
  ASSERT_EQ(spec.physics.bodies.size(), 1u);
  const BodySpec& b = spec.physics.bodies[0];
  ASSERT_TRUE(b.is_capsule());
  EXPECT_FALSE(b.motion.has_value());
  EXPECT_EQ(b.shape.type, ShapeSpec::Type::ellipse);
  EXPECT_DOUBLE_EQ(b.shape.aspect_ratio, 2.0);
  EXPECT_DOUBLE_EQ(b.membrane->capillary, 0.04);
  EXPECT_DOUBLE_EQ(b.membrane->bending_ratio, 0.4);
  EXPECT_EQ(b.membrane->reference_curvature, MembraneSpec::ReferenceCurvature::initial);
  EXPECT_EQ(b.membrane->nodes, 160);
  // The quick level halves the membrane nodes with the grid spacing.
  EXPECT_EQ(load_case(capsule_file, "quick").physics.bodies[0].membrane->nodes, 80);
  // Defaults are written back into the resolved case.
  json doc = capsule_json();
  doc["physics"]["bodies"][0]["membrane"].erase("reference_curvature");
  doc["physics"]["bodies"][0]["membrane"].erase("bending_ratio");
  const CaseSpec d = parse_case(doc, "edited.json", "standard", {});
  EXPECT_EQ(d.resolved["physics"]["bodies"][0]["membrane"]["reference_curvature"], "initial");
  EXPECT_EQ(d.resolved["physics"]["bodies"][0]["membrane"]["bending_ratio"], 0.0);
  EXPECT_EQ(d.resolved["physics"]["bodies"][0]["shape"]["angle"], 0.0);
}

TEST(case_capsule, RejectsABodyWithBothOrNeitherMotionAndMembrane) {
  json both = capsule_json();
  both["physics"]["bodies"][0]["motion"] = {{"type", "fixed"}};
  expect_doc_rejected(both, "/physics/bodies/0", {"both", "exactly one", "capsule"});
  json neither = capsule_json();
  neither["physics"]["bodies"][0].erase("membrane");
  expect_doc_rejected(neither, "/physics/bodies/0", {"neither", "rigid body"});
}

TEST(case_capsule, RejectsBadMembraneValues) {
  json doc = capsule_json();
  doc["physics"]["bodies"][0]["membrane"]["capillary"] = -0.04;
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/capillary", {"> 0"});
  doc = capsule_json();
  doc["physics"]["bodies"][0]["membrane"]["law"] = "skalak";
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/law", {"hooke"});
  doc = capsule_json();
  doc["physics"]["bodies"][0]["membrane"]["reference_curvature"] = "sphere";
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/reference_curvature", {"initial", "circle", "flat"});
  doc = capsule_json();
  doc["physics"]["bodies"][0]["membrane"]["stiffness"] = 1;
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/stiffness", {"unknown key", "capillary"});
}

TEST(case_capsule, RejectsAMembraneTooCoarseForTheGrid) {
  // 20 nodes on a 2:1 ellipse of equivalent radius 1: ~0.38 L apart, 7.7 fine spacings.
  expect_rejected([] { load_case(capsule_file, "standard", {"physics.bodies.0.membrane.nodes=20"}); },
                  "/physics/bodies/0/membrane/nodes", {"at least", "fine spacings", "leaks"});
}

TEST(case_capsule, RejectsACapsuleReachingOutOfTheFineBlock) {
  // The 2:1 ellipse reaches sqrt(2) = 1.41 from its centre: at x = 6.4 it crosses the margin
  // of the fine block [5, 11] although a circle of the same equivalent radius would fit.
  expect_rejected([] { load_case(capsule_file, "standard", {"physics.bodies.0.shape.center=[6.4, 8]"}); },
                  "/physics/bodies/0/shape/center", {"fine region", "reaching 1.414"});
}

TEST(case_capsule, RejectsUnsupportedCombinations) {
  json rigid_biconcave = cylinder_json();
  rigid_biconcave["physics"]["bodies"][0]["shape"]["type"] = "biconcave";
  expect_doc_rejected(rigid_biconcave, "/physics/bodies/0/shape/type", {"circle", "rigid body"});
  json sphere_capsule = capsule_json();
  sphere_capsule["physics"]["bodies"][0]["shape"]["type"] = "sphere";
  expect_doc_rejected(sphere_capsule, "/physics/bodies/0/shape/type", {"2D shape", "ellipse"});
  // A capsule quantity in a scene without capsules is an input error of the scene builder
  // (sim), not of the loader; the 2D ring law in 3D is refused here.
  json three_d = capsule_json();
  three_d["physics"]["dimension"] = 3;
  three_d["physics"]["domain"]["size"] = {16, 16, 16};
  three_d["physics"]["domain"]["boundaries"] = {"far_field", "far_field", "far_field"};
  three_d["physics"]["bodies"][0]["shape"]["type"] = "sphere";
  three_d["physics"]["bodies"][0]["shape"]["center"] = {8, 8, 8};
  three_d["physics"]["bodies"][0]["shape"].erase("aspect_ratio");
  three_d["numerics"]["grid"]["fine_region"] = {{"min", {5, 5, 5}}, {"max", {11, 11, 11}}};
  three_d["fidelity"] = {{"standard", json::object()}};
  three_d.erase("acceptance");
  expect_doc_rejected(three_d, "/physics/bodies/0/membrane/law", {"\"hooke\"", "neo_hookean", "in 3D"});
}

// ---------------------------------------------------------------- 3D capsules
const fs::path sphere_capsule_file = source_dir / "catalogue/ch5/sphere_nh_G0.05.json";
json sphere_capsule_json() { return read_case_json(sphere_capsule_file); }
json& membrane_of(json& doc) { return doc["physics"]["bodies"][0]["membrane"]; }

TEST(case_capsule3d, LoadsLawMeshAndShape) {
  const CaseSpec spec = load_case(sphere_capsule_file, "standard");
  const BodySpec& b = spec.physics.bodies.at(0);
  ASSERT_TRUE(b.is_capsule());
  EXPECT_EQ(b.shape.type, ShapeSpec::Type::sphere);
  EXPECT_EQ(b.membrane->law, MembraneSpec::Law::neo_hookean);
  EXPECT_EQ(b.membrane->subdivisions, 5);
  EXPECT_EQ(b.membrane->nodes, 0);
  EXPECT_EQ(load_case(sphere_capsule_file, "quick").physics.bodies[0].membrane->subdivisions, 4);
  // The 2D bending keys are not written into a 3D case.
  EXPECT_FALSE(spec.resolved["physics"]["bodies"][0]["membrane"].contains("bending_ratio"));
  const CaseSpec sk = load_case(source_dir / "catalogue/ch5/biconcave_sk_G0.6.json", "standard");
  EXPECT_EQ(sk.physics.bodies[0].membrane->law, MembraneSpec::Law::skalak);
  EXPECT_DOUBLE_EQ(sk.physics.bodies[0].membrane->area_dilation, 200.0);
  EXPECT_EQ(sk.physics.bodies[0].shape.type, ShapeSpec::Type::biconcave_discoid);
}

TEST(case_capsule3d, RejectsKeysOfTheOtherDimensionOrLaw) {
  json doc = sphere_capsule_json();
  membrane_of(doc)["nodes"] = 4098;
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/nodes", {"no \"nodes\"", "2D capsules", "subdivisions"});
  doc = sphere_capsule_json();
  membrane_of(doc).erase("subdivisions");
  expect_doc_rejected(doc, "/physics/bodies/0/membrane", {"\"subdivisions\"", "required", "3D capsules"});
  doc = sphere_capsule_json();
  membrane_of(doc)["area_dilation"] = 1;
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/area_dilation", {"\"skalak\"", "eq. 5.3"});
  doc = sphere_capsule_json();
  membrane_of(doc)["law"] = "skalak";
  expect_doc_rejected(doc, "/physics/bodies/0/membrane", {"\"area_dilation\"", "required"});
  doc = sphere_capsule_json();
  membrane_of(doc)["bending_ratio"] = 0.01;
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/bending_ratio", {"no bending stiffness"});
  doc = sphere_capsule_json();
  membrane_of(doc)["area_dilation"] = -1;
  membrane_of(doc)["law"] = "skalak";
  expect_doc_rejected(doc, "/physics/bodies/0/membrane/area_dilation", {"> 0"});
}

TEST(case_capsule3d, RejectsACoarseMeshAnd2DShapesAndRigidSpheroids) {
  // n = 2: 66 nodes on the sphere of radius 1, mean edge ~0.36 L = 4.4 fine spacings at a/12.
  expect_rejected([] { load_case(sphere_capsule_file, "standard", {"physics.bodies.0.membrane.subdivisions=2"}); },
                  "/physics/bodies/0/membrane/subdivisions", {"at least 4 subdivisions", "fine spacings", "leaks"});
  expect_rejected([] { load_case(sphere_capsule_file, "standard", {"physics.bodies.0.shape.type=ellipse"}); },
                  "/physics/bodies/0/shape/type", {"3D shape", "\"oblate_spheroid\""});
  json rigid = sphere_capsule_json();
  rigid["physics"]["bodies"][0].erase("membrane");
  rigid["physics"]["bodies"][0]["motion"] = {{"type", "fixed"}};
  rigid["physics"]["bodies"][0]["shape"]["type"] = "oblate_spheroid";
  expect_doc_rejected(rigid, "/physics/bodies/0/shape/type", {"rigid body", "capsule shape"});
}

TEST(case_capsule3d, RejectsAnOblateCapsuleReachingOutOfTheFineBlock) {
  // A 2:1 oblate spheroid of equivalent radius 1 has the equatorial radius 2^(1/3) = 1.26.
  expect_rejected(
      [] {
        load_case(sphere_capsule_file, "standard",
                  {"physics.bodies.0.shape.type=oblate_spheroid", "physics.bodies.0.shape.aspect_ratio=2",
                   "physics.bodies.0.shape.center=[4.4, 5, 5]"});
      },
      "/physics/bodies/0/shape/center", {"fine region", "reaching 1.26"});
}

// ---------------------------------------------------------------- moving rigid bodies

/// The cylinder case with the cylinder moving along x from its centre (10, 10) by `x`, a formula
/// of T: T is t until t = 20, then 20 (at rest, so the path is continuous).
json moving_json(const std::string& x = "10 + 0.5*sin(omega*T)") {
  auto at = [&](const std::string& time) {
    std::string f = x;
    for (std::size_t p = f.find('T'); p != std::string::npos; p = f.find('T', p + time.size()))
      f.replace(p, 1, time);
    return f;
  };
  json doc = cylinder_json();
  doc["physics"]["bodies"][0]["motion"] = {
      {"type", "prescribed"},
      {"parameters", {{"omega", 0.5}}},
      {"segments", json::array({{{"until", 20.0}, {"position", {at("t"), "10"}}},
                                {{"position", {at("20"), "10"}}}})}};
  return doc;
}

TEST(case_motion, PrescribedKinematicsAreExact) {
  const CaseSpec spec = parse_case(moving_json(), "moving.json", "standard", {});
  const auto& body = spec.physics.bodies.at(0);
  ASSERT_TRUE(body.is_moving());
  const auto pose = body.motion->kinematics->at(3.0);
  EXPECT_NEAR(pose.x[0], 10 + 0.5 * std::sin(1.5), 1e-14);
  EXPECT_NEAR(pose.v[0], 0.25 * std::cos(1.5), 1e-14);
  EXPECT_NEAR(pose.a[0], -0.125 * std::sin(1.5), 1e-14);
  EXPECT_EQ(pose.v[1], 0.0);
  EXPECT_EQ(pose.angle, 0.0);  // no "angle": the shape's orientation, constant
  const auto later = body.motion->kinematics->at(30.0);  // second segment: at rest
  EXPECT_NEAR(later.x[0], 10 + 0.5 * std::sin(10.0), 1e-14);
  EXPECT_EQ(later.v[0], 0.0);
}

TEST(case_motion, RejectsBadFormulasWithTheirPathAndPlace) {
  expect_doc_rejected(moving_json("10 + 0.5*sin(omeg*T)"), "/physics/bodies/0/motion/segments/0/position/0",
                      {"unknown name 'omeg'", "omega", "^"});
  expect_doc_rejected(moving_json("10 + (T"), "/physics/bodies/0/motion/segments/0/position/0", {"expected ')'"});
}

TEST(case_motion, RejectsInconsistentSegments) {
  json no_segments = moving_json();
  no_segments["physics"]["bodies"][0]["motion"].erase("segments");
  expect_doc_rejected(no_segments, "/physics/bodies/0/motion/segments", {"non-empty array", "prescribed"});
  json open_end = moving_json();
  open_end["physics"]["bodies"][0]["motion"]["segments"][1]["until"] = 40;
  expect_doc_rejected(open_end, "/physics/bodies/0/motion/segments/1/until", {"last segment"});
  json backwards = moving_json();
  backwards["physics"]["bodies"][0]["motion"]["segments"].insert(
      backwards["physics"]["bodies"][0]["motion"]["segments"].begin() + 1,
      json{{"until", 10.0}, {"position", {"10 + 0.5*sin(omega*t)", "10"}}});
  expect_doc_rejected(backwards, "/physics/bodies/0/motion/segments/1/until", {"after the previous segment"});
  json fixed_with_segments = moving_json();
  fixed_with_segments["physics"]["bodies"][0]["motion"]["type"] = "fixed";
  expect_doc_rejected(fixed_with_segments, "/physics/bodies/0/motion/segments", {"prescribed"});
}

TEST(case_motion, RejectsAPathThatJumpsStartsElsewhereOrLeavesTheFineRegion) {
  json jump = moving_json();
  jump["physics"]["bodies"][0]["motion"]["segments"][1]["position"][0] = "11";
  expect_doc_rejected(jump, "/physics/bodies/0/motion/segments/1", {"continuous at t = 20", "x position"});
  expect_doc_rejected(moving_json("11 + 0.5*sin(omega*T)"), "/physics/bodies/0/motion/segments",
                      {"starts at its shape.center", "shape.center has 10"});
  // Amplitude 3: the cylinder (fine region [8, 16] x [8, 12]) leaves it on the left.
  expect_doc_rejected(moving_json("10 - 3*sin(omega*T)"), "/physics/bodies/0/motion/segments",
                      {"inside the fine region", "at t = "});
  // sqrt of a negative number between t = 5 and 15.
  expect_doc_rejected(moving_json("10 + 0*sqrt((T - 5)*(T - 15))"), "/physics/bodies/0/motion/segments",
                      {"not finite at t = 5"});
}

TEST(case_acceptance, TimeSeriesEntriesTakeAWindowAndNoReferenceValue) {
  json doc = cylinder_json();
  json entry = {{"metric", "drag_coefficient"},
                {"reference", "references/cylinder/some_history.csv#t:cd"},
                {"comparison", "time_series"},
                {"window", {150, 250}},
                {"tolerance", {{"quick", 0.1}, {"standard", 0.1}, {"thesis", 0.1}}},
                {"justification", "test"}};
  doc["acceptance"] = json::array({entry});
  const CaseSpec spec = parse_case(doc, "series.json", "standard", {});
  ASSERT_EQ(spec.acceptance.size(), 1U);
  EXPECT_EQ(spec.acceptance[0].window, (std::vector<double>{150, 250}));
  json with_value = doc;
  with_value["acceptance"][0]["reference_value"] = 1.4;
  expect_doc_rejected(with_value, "/acceptance/0/reference_value", {"the reference history"});
  json backwards = doc;
  backwards["acceptance"][0]["window"] = {250, 150};
  expect_doc_rejected(backwards, "/acceptance/0/window", {"from < to"});
  json beyond = doc;
  beyond["acceptance"][0]["window"] = {150, 300};
  expect_doc_rejected(beyond, "/acceptance/0/window", {"inside the run"});
  json numeric_window = cylinder_json();
  numeric_window["acceptance"][0]["window"] = {150, 250};
  expect_doc_rejected(numeric_window, "/acceptance/0/window", {"remove it"});
  // The same metric may be scored against two references, not twice against one.
  json twice = doc;
  twice["acceptance"].push_back(entry);
  expect_doc_rejected(twice, "/acceptance/1/metric", {"same reference"});
  twice["acceptance"][1]["reference"] = "references/cylinder/other_history.csv#t:cd";
  EXPECT_NO_THROW(parse_case(twice, "series.json", "standard", {}));
}

}  // namespace
}  // namespace caplab::cases
