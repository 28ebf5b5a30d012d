// Hostile input to the case loader (DESIGN.md section 5): catalogue cases mutated at every path
// (wrong types, missing keys), non-finite and absurd numbers in the file and in `--set`, bodies
// outside the domain or the fine block, empty arrays, repeated keys, runaway nesting, bytes that
// are not UTF-8, empty, truncated and non-regular files, and the inputs the fuzzer
// (tests/fuzz/fuzz_case.cpp) found. Every one must be a core::InputError whose message names the
// file, the JSON path and the offending value — the assertions read the message, not only the type.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "case/case_diagnostics.hpp"
#include "case/case_schema.hpp"
#include "case/load_case.hpp"
#include "core/error.hpp"

namespace caplab::cases {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

const fs::path source_dir{CAPLAB_SOURCE_DIR};
const fs::path cylinder_file = source_dir / "catalogue/ch2/cylinder_re100.json";
const fs::path sphere_file = source_dir / "catalogue/ch5/sphere_nh_G0.05.json";
const fs::path capsule_file = source_dir / "catalogue/ch3/circle_G0.04_Eb0.json";
const fs::path wing_file = source_dir / "catalogue/ch2/hovering_wing_re157.json";
constexpr const char* mutated = "mutated.json";

std::string text_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Runs `f`; expects a core::InputError whose message contains every one of `words`, and
/// returns it (empty after a failure).
std::string rejection(const std::function<void()>& f, const std::vector<std::string>& words) {
  try {
    f();
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    for (const auto& w : words)
      EXPECT_NE(what.find(w), std::string::npos) << "no \"" << w << "\" in: " << what;
    EXPECT_TRUE(is_utf8(what)) << what;
    if (std::getenv("CAPLAB_PRINT_ERRORS")) std::printf("%s\n", what.c_str());
    return what;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "accepted, but it should be rejected";
  return "";
}

/// The text `text` loaded as the file "mutated.json" must be rejected naming the file and `words`.
std::string text_rejected(const std::string& text, const std::vector<std::string>& words,
                          const std::vector<std::string>& overrides = {}) {
  std::vector<std::string> all{mutated};
  all.insert(all.end(), words.begin(), words.end());
  return rejection([&] { load_case_text(text, mutated, "standard", overrides); }, all);
}

/// `file` with the override must be rejected at `path` with `words` in the message; the
/// message names the file and the path (and the override, when it set the value at fault).
void set_rejected(const fs::path& file, const std::string& override_text, const std::string& path,
                  const std::vector<std::string>& words) {
  SCOPED_TRACE(printable(override_text));
  std::vector<std::string> all{file.filename().string(), path};
  all.insert(all.end(), words.begin(), words.end());
  rejection([&] { load_case(file, "standard", {override_text}); }, all);
}

// ---------------------------------------------------------------- every path of a real case

// The pointers of every value under the sections a case author writes (the free-text fields
// and the fidelity levels aside: their values are "any").
void collect(const json& v, const std::string& at, std::vector<std::string>& out) {
  out.push_back(at);
  if (v.is_object())
    for (const auto& item : v.items()) collect(item.value(), child_pointer(at, item.key()), out);
  if (v.is_array())
    for (std::size_t i = 0; i < v.size(); ++i) collect(v[i], child_pointer(at, i), out);
}

std::vector<std::string> paths_of(const json& doc) {
  std::vector<std::string> out;
  for (const char* section : {"physics", "numerics", "outputs", "acceptance"})
    if (doc.contains(section)) collect(doc.at(section), std::string("/") + section, out);
  return out;
}

// A value of another JSON type than `v` (so that the schema must reject it).
json wrong_type(const json& v) {
  if (v.is_number()) return "12";
  if (v.is_string()) return true;
  if (v.is_array()) return json::object();
  if (v.is_object()) return json::array({1});
  return "x";
}

class case_malformed_paths : public ::testing::TestWithParam<fs::path> {};

TEST_P(case_malformed_paths, EveryValueOfTheWrongTypeIsRejectedAtItsPath) {
  const json doc = read_case_json(GetParam());
  for (const auto& path : paths_of(doc)) {
    const json::json_pointer pointer(path);
    // reference_mode takes a name or an array of names: another array is checked elsewhere.
    if (path.find("reference_mode") != std::string::npos) continue;
    json bad = doc;
    bad[pointer] = wrong_type(doc[pointer]);
    SCOPED_TRACE(path + " = " + bad[pointer].dump());
    // The value as written; a fidelity level that writes below a container may be the first
    // to trip over it, and then its message names the container's path.
    text_rejected(bad.dump(2), {path, describe(bad[pointer])});
  }
}

TEST_P(case_malformed_paths, EveryRequiredKeyMissingIsNamed) {
  const json doc = read_case_json(GetParam());
  int checked = 0;
  for (const auto& key : schema_keys()) {
    if (!key.required || key.path.find('*') != std::string::npos) continue;
    std::string pointer;
    for (std::size_t start = 0;;) {
      const std::size_t dot = key.path.find('.', start);
      pointer = child_pointer(pointer, key.path.substr(start, dot == std::string::npos ? dot : dot - start));
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    const json::json_pointer p(pointer);
    if (!doc.contains(p)) continue;  // inside an optional object the case does not have
    json bad = doc;
    bad[p.parent_pointer()].erase(p.back());
    SCOPED_TRACE(pointer);
    text_rejected(bad.dump(2), {pointer, "nothing (required key \"" + p.back() + "\" is missing)"});
    ++checked;
  }
  EXPECT_GE(checked, 20);
}

// Required keys inside array entries (bodies, segments, acceptance entries).
TEST(case_malformed, RequiredKeysOfArrayEntriesMissing) {
  const json doc = read_case_json(cylinder_file);
  for (const std::string path :
       {"/physics/bodies/0/name", "/physics/bodies/0/shape/center", "/physics/bodies/0/shape/diameter",
        "/physics/bodies/0/motion/type", "/acceptance/0/metric", "/acceptance/0/justification"}) {
    SCOPED_TRACE(path);
    json bad = doc;
    const json::json_pointer p(path);
    bad[p.parent_pointer()].erase(p.back());
    text_rejected(bad.dump(), {path, "is missing"});
  }
}

INSTANTIATE_TEST_SUITE_P(catalogue, case_malformed_paths,
                         ::testing::Values(cylinder_file, sphere_file, capsule_file, wing_file),
                         [](const auto& p) {
                           std::string name = p.param.stem().string();
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

// ---------------------------------------------------------------- numbers JSON does not have

// Replaces the first `"key": <number>` of `text` by `"key": replacement`.
std::string with_number(std::string text, const std::string& key, const std::string& replacement) {
  const std::string needle = "\"" + key + "\": ";
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << key;
  const std::size_t start = at + needle.size();
  const std::size_t end = text.find_first_of(",\n}", start);
  return text.replace(start, end - start, replacement);
}

TEST(case_malformed, NanInfinityAndOverflowInTheFileNameTheLineThePathAndTheText) {
  const std::string text = text_of(cylinder_file);
  for (const std::string bad : {"NaN", "nan", "Infinity", "-Infinity", "inf", "1e999", "-1e999", "0x10", "+1",
                                "01", "1.", ".5", "1e", "--1"}) {
    SCOPED_TRACE(bad);
    // The offending text as written, where the parser stopped, and the line and column.
    const bool overflow = bad.find("e999") != std::string::npos;
    text_rejected(with_number(text, "reynolds", bad), {"malformed JSON", "near /physics/reynolds",
                                                       overflow ? "'" + bad + "'" : "at `" + bad + "`",
                                                       overflow ? "number overflow" : "line 15, column"});
  }
  // Numbers a double holds but the format does not allow: the value and the range.
  text_rejected(with_number(text, "lattice_velocity", "1e308"),
                {"/numerics/lattice_velocity", "1e+308", "in (0, 0.4]"});
  text_rejected(with_number(text, "reynolds", "-1e308"),
                {"/physics/reynolds", "-1e+308", "a finite number > 0"});
  text_rejected(with_number(text, "fine_spacing", "4.9e-324"),
                {"/numerics/grid/fine_spacing", "lattice nodes"});
}

TEST(case_malformed, NanAndInfinityThroughOverrides) {
  for (const std::string value : {"nan", "NaN", "inf", "-inf", "Infinity", "-Infinity", "1e999", "-1e999"}) {
    set_rejected(cylinder_file, "physics.reynolds=" + value, "/physics/reynolds",
                 {"NaN and infinity are not allowed", "a finite number > 0"});
    set_rejected(sphere_file, "numerics.end_time=" + value, "/numerics/end_time", {"NaN and infinity"});
    set_rejected(sphere_file, "physics.bodies.0.shape.center.1=" + value, "/physics/bodies/0/shape/center/1",
                 {"NaN and infinity"});
  }
  set_rejected(cylinder_file, "physics.domain.size=[30, 1e999]", "/physics/domain/size", {"1e999"});
}

// ---------------------------------------------------------------- values out of range

TEST(case_malformed, ZeroAndNegativeSpacingsSizesAndTimes) {
  struct Bad {
    const char* set;
    const char* path;
    const char* expected;
  };
  for (const Bad& b : {
           Bad{"numerics.grid.fine_spacing=0", "/numerics/grid/fine_spacing", "> 0"},
           Bad{"numerics.grid.fine_spacing=-0.02", "/numerics/grid/fine_spacing", "> 0"},
           Bad{"numerics.grid.fine_spacing=-0", "/numerics/grid/fine_spacing", "> 0"},
           Bad{"physics.domain.size.0=0", "/physics/domain/size/0", "> 0"},
           Bad{"physics.domain.size.1=-20", "/physics/domain/size/1", "> 0"},
           Bad{"numerics.end_time=0", "/numerics/end_time", "> 0"},
           Bad{"numerics.end_time=-250", "/numerics/end_time", "> 0"},
           Bad{"outputs.series.interval=0", "/outputs/series/interval", "> 0"},
           Bad{"outputs.snapshots.times.0=-1", "/outputs/snapshots/times/0", ">= 0"},
           Bad{"outputs.average_from=-1", "/outputs/average_from", ">= 0"},
           Bad{"physics.bodies.0.shape.diameter=0", "/physics/bodies/0/shape/diameter", "> 0"},
           Bad{"numerics.lattice_velocity=0", "/numerics/lattice_velocity", "in (0, 0.4]"},
           Bad{"numerics.ib.marker_spacing=-1", "/numerics/ib/marker_spacing", "in [0.05, 2]"},
           Bad{"numerics.ib.marker_spacing=1e-300", "/numerics/ib/marker_spacing", "in [0.05, 2]"},
           Bad{"numerics.threads=-1", "/numerics/threads", "in [0, 4096]"},
           Bad{"numerics.threads=100000", "/numerics/threads", "in [0, 4096]"},
           Bad{"numerics.threads=18446744073709551615", "/numerics/threads", "in [0, 4096]"},
           Bad{"numerics.ib.forcing_iterations=1000000000", "/numerics/ib/forcing_iterations", "in [1, 100]"},
           Bad{"physics.reynolds=0", "/physics/reynolds", "> 0"},
       }) {
    set_rejected(cylinder_file, b.set, b.path, {b.expected});
  }
  // An int field: 2^32 would wrap to 0 and the run's guard check `step % every` divide by zero.
  set_rejected(cylinder_file, "numerics.guards.every=4294967296", "/numerics/guards/every",
               {"in [1, 1000000000]"});
  set_rejected(sphere_file, "physics.bodies.0.membrane.capillary=0", "/physics/bodies/0/membrane/capillary",
               {"> 0"});
  set_rejected(sphere_file, "physics.bodies.0.membrane.subdivisions=99",
               "/physics/bodies/0/membrane/subdivisions", {"in [1, 7]"});
  set_rejected(capsule_file, "physics.bodies.0.membrane.nodes=2147483648", "/physics/bodies/0/membrane/nodes",
               {"in [8, 1000000]"});
}

TEST(case_malformed, HugeDomainsAndResolutionsAreRefusedBeforeAnythingIsAllocated) {
  set_rejected(cylinder_file, "numerics.grid.fine_spacing=1e-7", "/numerics/grid/fine_spacing",
               {"1e-07", "at most 2e+09 lattice nodes"});
  set_rejected(cylinder_file, "physics.domain.size=[1e300, 1e300]", "/numerics/grid/fine_spacing",
               {"0.02", "lattice nodes; this one gives inf"});
  set_rejected(sphere_file, "physics.domain.size=[1e308, 1e308, 1e308]", "/numerics/grid/fine_spacing",
               {"lattice nodes"});
  set_rejected(sphere_file, "numerics.grid.fine_spacing=0.001", "/numerics/grid/fine_spacing",
               {"at most 2e+09 lattice nodes"});
}

// ---------------------------------------------------------------- geometry

TEST(case_malformed, BodiesOutsideTheDomainOrTheFineBlock) {
  set_rejected(
      cylinder_file, "physics.bodies.0.shape.center=[0.2, 10]", "/physics/bodies/0/shape/center",
      {"[0.2,10.0]", "--set physics.bodies.0.shape.center=[0.2, 10]", "inside the domain", "along x"});
  set_rejected(cylinder_file, "physics.bodies.0.shape.center=[-50, 10]", "/physics/bodies/0/shape/center",
               {"[-50.0,10.0]", "inside the domain"});
  set_rejected(cylinder_file, "physics.bodies.0.shape.center=[10, 1e300]", "/physics/bodies/0/shape/center",
               {"inside the domain", "along y"});
  set_rejected(cylinder_file, "physics.bodies.0.shape.center=[15.8, 10]", "/physics/bodies/0/shape/center",
               {"[15.8,10.0]", "inside the fine region"});
  set_rejected(cylinder_file, "physics.bodies.0.shape.diameter=100", "/physics/bodies/0/shape/center",
               {"inside the domain"});
  set_rejected(sphere_file, "physics.bodies.0.shape.center=[5, 5, 6.5]", "/physics/bodies/0/shape/center",
               {"[5.0,5.0,6.5]", "inside the fine region", "along z"});
  set_rejected(sphere_file, "physics.bodies.0.shape.center=[5, 5, 11]", "/physics/bodies/0/shape/center",
               {"inside the domain", "along z"});
  set_rejected(capsule_file, "physics.bodies.0.shape.center=[11, 8]", "/physics/bodies/0/shape/center",
               {"inside the fine region"});
  // A fine block reaching out of the domain, or inside out.
  set_rejected(sphere_file, "numerics.grid.fine_region.max.0=20", "/numerics/grid/fine_region/max/0",
               {"20", "inside the domain"});
  set_rejected(sphere_file, "numerics.grid.fine_region.min=[7, 3, 3]", "/numerics/grid/fine_region",
               {"min < max"});
  // A moving body whose path leaves the fine block during the run (stroke along x from x0 + A0 to
  // x0 and back), and one whose path does not start where its shape is.
  rejection(
      [] {
        load_case(wing_file, "standard",
                  {"physics.bodies.0.motion.parameters.beta=0", "physics.bodies.0.motion.parameters.x0=5.5",
                   "physics.bodies.0.shape.center=[8, 7]"});
      },
      {"hovering_wing_re157.json", "/physics/bodies/0/motion/segments", "inside the fine region", "at t = "});
  set_rejected(wing_file, "physics.bodies.0.motion.parameters.A0=50", "/physics/bodies/0/motion/segments",
               {"x0 + 0.5*A0", "starts at its shape.center"});
}

// ---------------------------------------------------------------- empty and repeated

TEST(case_malformed, EmptyArraysWhereEntriesAreNeeded) {
  set_rejected(cylinder_file, "physics.domain.size=[]", "/physics/domain/size",
               {"[]", "2 entries, one per axis"});
  set_rejected(cylinder_file, "physics.domain.boundaries=[]", "/physics/domain/boundaries", {"2 entries"});
  set_rejected(cylinder_file, "physics.bodies.0.shape.center=[]", "/physics/bodies/0/shape/center",
               {"2 entries"});
  set_rejected(sphere_file, "numerics.grid.fine_region.min=[]", "/numerics/grid/fine_region/min",
               {"3 entries"});
  set_rejected(wing_file, "physics.bodies.0.motion.segments=[]", "/physics/bodies/0/motion/segments",
               {"a non-empty array of segments"});
  set_rejected(sphere_file, "acceptance.0.reference_mode=[]", "/acceptance/0/reference_mode", {"[]"});
  // An override into an empty array names the array.
  set_rejected(cylinder_file, "physics.domain.size=[]", "/physics/domain/size", {"[]"});
  rejection(
      [] {
        load_case(cylinder_file, "standard", {"physics.bodies=[]", "physics.bodies.0.name=x"});
      },
      {"--set physics.bodies.0.name=x", "empty or absent"});
}

TEST(case_malformed, EmptyStringsAndUnknownSnapshotFields) {
  set_rejected(cylinder_file, "id=\"\"", "/id", {"a non-empty string"});
  set_rejected(cylinder_file, "physics.bodies.0.name=\"\"", "/physics/bodies/0/name", {"a non-empty string"});
  set_rejected(cylinder_file, "outputs.snapshots.fields=[\"vorticty\"]", "/outputs/snapshots/fields/0",
               {"\"vorticty\"", "did you mean \"vorticity\"?"});
}

TEST(case_malformed, KeysRepeatedInTheFileOrInAnOverride) {
  std::string text = text_of(cylinder_file);
  text.replace(text.find("\"reynolds\": 100,"), 16, "\"reynolds\": 100, \"reynolds\": 200,");
  text_rejected(text, {"/physics/reynolds", "the key \"reynolds\" a second time"});
  set_rejected(cylinder_file, "numerics.ib={\"kernel\": \"cosine4\", \"kernel\": \"cosine4\"}", "/",
               {"the key \"kernel\" a second time", "/kernel"});
}

// ---------------------------------------------------------------- garbage

TEST(case_malformed, DeepNestingIsRefusedWhileParsing) {
  for (const std::size_t depth : {std::size_t{65}, std::size_t{100000}}) {
    SCOPED_TRACE(depth);
    const std::string arrays = std::string(depth, '[') + std::string(depth, ']');
    text_rejected(arrays, {"nested more than 64 deep", "at most 64 levels"});
    text_rejected("{\"id\": " + arrays + "}", {"nested more than 64 deep", "/id/0/0"});
    std::string objects;
    for (std::size_t i = 0; i < depth; ++i) objects += "{\"a\":";
    text_rejected(objects, {"nested more than 64 deep", "/a/a/a"});  // and unterminated
    set_rejected(cylinder_file, "physics.bodies=" + arrays, "/",
                 {"--set physics.bodies=[[[[", "nested more than 64 deep"});
  }
  // 63 levels is merely a wrong value.
  const std::string fine = std::string(63, '[') + std::string(63, ']');
  set_rejected(cylinder_file, "id=" + fine, "/id", {"(an array)", "a non-empty string"});
}

TEST(case_malformed, TopLevelValuesThatAreNotACase) {
  for (const std::string text : {"[]", "null", "42", "\"case\"", "true", "[{}]"}) {
    SCOPED_TRACE(text);
    text_rejected(text, {"at /", "an object with keys \"id\""});
  }
  text_rejected("{}", {"/fidelity", "is missing"});
  text_rejected("{\"fidelity\": {}}", {"/fidelity", "a level this case defines: (none)"});
  text_rejected("{\"fidelity\": {\"standard\": {}}}", {"/id", "is missing"});
  text_rejected("{\"fidelity\": {\"standard\": []}}", {"/fidelity/standard", "(an array)"});
}

TEST(case_malformed, BytesThatAreNotUtf8) {
  std::string text = text_of(cylinder_file);
  for (const std::string bad : {"\xff", "\xc0\xaf", "\xed\xa0\x80", "\xe2\x82", "\x80"}) {
    SCOPED_TRACE(printable(bad));
    std::string in_string = text;
    in_string.insert(in_string.find("cylinder\""), bad);
    const std::string what = text_rejected(in_string, {"malformed JSON", "ill-formed UTF-8", "near /"});
    std::string outside = text;
    outside.insert(outside.find("\"physics\""), bad);
    text_rejected(outside, {"malformed JSON", "line"});
  }
  // A byte order mark is allowed by the parser, a NUL byte is not.
  text_rejected(std::string("{\"id\": \"a\0b\"}", 13), {"malformed JSON", "control character"});
  // In an override (from a shell, any bytes): named with \xNN, never copied into the message.
  set_rejected(cylinder_file, "physics.reynolds=\xff\xfe", "",
               {"--set physics.reynolds=\\xff\\xfe", "UTF-8"});
  set_rejected(cylinder_file, "id=\xc3", "", {"--set id=\\xc3", "UTF-8"});
}

TEST(case_malformed, MalformedOverrides) {
  for (const std::string bad : {"", "=", " =1", "\t=1", "physics.reynolds", "=100", " \t =100"}) {
    SCOPED_TRACE(bad);
    rejection([&] { load_case(cylinder_file, "standard", {bad}); },
              {"--set " + printable(bad), "an override of the form path=value"});
  }
  set_rejected(cylinder_file, "physics..reynolds=1", "/physics/", {"a dotted path"});
  set_rejected(cylinder_file, "physics.reynolds.x=1", "/physics/reynolds/x", {"has no member \"x\""});
  set_rejected(cylinder_file, "physics.bodies.99999999999=1", "/physics/bodies/99999999999",
               {"an index 0..0"});
  set_rejected(cylinder_file, "physics.bodies.-1=1", "/physics/bodies/-1", {"an index 0..0"});
  set_rejected(cylinder_file, "fidelity.quick.numerics.end_time=1", "/fidelity",
               {"a path outside \"fidelity\""});
}

// ---------------------------------------------------------------- files

class TempPath {
 public:
  explicit TempPath(const std::string& name)
      : path_(fs::temp_directory_path() / ("caplab_malformed_" + std::to_string(::getpid()) + "_" + name)) {}
  ~TempPath() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

TEST(case_malformed, EmptyBlankTruncatedAndMissingFiles) {
  const TempPath file("case.json");
  write(file.path(), "");
  rejection([&] { load_case(file.path()); }, {file.path().string(), "the case file is empty"});
  write(file.path(), " \n\t\r\n");
  rejection([&] { load_case(file.path()); }, {file.path().string(), "the case file is blank"});
  const std::string text = text_of(cylinder_file);
  for (const std::size_t cut : {std::size_t{1}, std::size_t{700}, text.size() / 2, text.size() - 2}) {
    SCOPED_TRACE(cut);
    write(file.path(), text.substr(0, cut));
    rejection([&] { load_case(file.path()); }, {file.path().string(), "malformed JSON", "line"});
  }
  write(file.path(), text.substr(0, text.size() - 2));
  rejection([&] { load_case(file.path()); }, {"near /acceptance", "unexpected end of input"});
  rejection([] { load_case(source_dir / "catalogue/ch2/no_such_case.json"); },
            {"no_such_case.json", "no such file"});
}

TEST(case_malformed, DirectoriesAndOtherNonRegularFiles) {
  rejection([] { load_case(source_dir / "catalogue"); }, {"catalogue", "not a regular file"});
  rejection([] { load_case("/dev/null"); }, {"/dev/null", "not a regular file"});
  const TempPath link("dangling.json");
  fs::create_symlink("/nonexistent/caplab_case.json", link.path());
  rejection([&] { load_case(link.path()); }, {link.path().string(), "no such file"});
}

TEST(case_malformed, FilesTooLargeToBeACaseAreNotRead) {
  const TempPath file("huge.json");
  { std::ofstream(file.path(), std::ios::binary); }
  fs::resize_file(file.path(), max_case_file_bytes + 1);  // sparse: costs no disk
  rejection([&] { load_case(file.path()); }, {file.path().string(), "more than the 16 MiB"});
}

TEST(case_malformed, TooManyFidelityLevels) {
  json doc = read_case_json(cylinder_file);
  for (int i = 0; i < 20; ++i) doc["fidelity"]["level" + std::to_string(i)] = json::object();
  text_rejected(doc.dump(), {"/fidelity", "23 fidelity levels", "at most 16"});
}

// ---------------------------------------------------------------- the same code path

TEST(case_malformed, TextAndFileLoadTheSameCase) {
  const CaseSpec from_file = load_case(sphere_file, "quick", {"numerics.end_time=10"});
  const CaseSpec from_text =
      load_case_text(text_of(sphere_file), sphere_file.string(), "quick", {"numerics.end_time=10"});
  EXPECT_EQ(from_file.resolved, from_text.resolved);
  EXPECT_EQ(from_file.source_file, from_text.source_file);
}

TEST(case_malformed, PrintableKeepsUtf8AndEscapesTheRest) {
  EXPECT_EQ(printable("a\xff"
                      "b\n"),
            "a\\xffb\\x0a");
  EXPECT_EQ(printable("\xc3\xa9t\xc3\xa9"), "\xc3\xa9t\xc3\xa9");
  EXPECT_EQ(printable(std::string(300, 'x'), 10), "xxxxxxx...");
  EXPECT_EQ(printable("\xc3\xa9\xc3\xa9\xc3\xa9", 6), "\xc3\xa9\xc3\xa9\xc3\xa9");
  EXPECT_EQ(printable("\xc3\xa9\xc3\xa9\xc3\xa9", 5), "\xc3\xa9...");  // never cuts a character
  EXPECT_TRUE(is_utf8("\xf0\x9f\x98\x80"));
  EXPECT_FALSE(is_utf8("\xf0\x9f\x98"));
  EXPECT_FALSE(is_utf8("\xed\xa0\x80"));  // a UTF-16 surrogate
  EXPECT_FALSE(is_utf8("\xc1\xbf"));      // overlong
}

}  // namespace
}  // namespace caplab::cases
