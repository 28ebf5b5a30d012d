// Lattice units of a case: the memory estimate (populations in one buffer, force density,
// forced-node bookkeeping, snapshot scratch), the refusal of cases that do not fit in the
// machine's memory, and the refusal of runs whose step count no integer holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../../fuzz/fuzz_input.hpp"
#include "case/load_case.hpp"
#include "core/error.hpp"
#include "membrane/fem_membrane.hpp"
#include "sim/units.hpp"

namespace caplab::sim {
namespace {

namespace fs = std::filesystem;
const fs::path source_dir{CAPLAB_SOURCE_DIR};
const fs::path cylinder_file = source_dir / "catalogue/ch2/cylinder_re100.json";
const fs::path sphere_file = source_dir / "catalogue/ch5/sphere_nh_G0.05.json";
constexpr double gib = 1024.0 * 1024.0 * 1024.0;

double with_ghosts(const BlockUnits& b) {
  double n = 1;
  for (int k : b.nodes) n *= k + 2;
  return n;
}

// derive_units must refuse `spec` with an InputError at `path` whose message contains `text`.
void expect_refused(const cases::CaseSpec& spec, const std::string& path, const std::string& text) {
  try {
    derive_units(spec);
    ADD_FAILURE() << "accepted; expected a refusal at " << path;
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.json_path(), path);
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(sim_units, MemoryEstimateCountsWhatScalesWithTheLattice) {
  const auto spec = cases::load_case(cylinder_file, "standard");  // 2D, double, one fixed body, snapshots
  const auto u = derive_units(spec);
  ASSERT_EQ(u.blocks.size(), 2u);
  const double nc = with_ghosts(u.blocks[0]), nf = with_ghosts(u.blocks[1]);
  const double populations = (nc + nf) * 9 * 8;  // one buffer, in place
  const double force = nf * 2 * 8, bookkeeping = nf * 8;
  const double snapshot = std::max(nc, nf) * 8 * (1 + 2 + 1 + 1);
  EXPECT_DOUBLE_EQ(u.memory_bytes, populations + force + bookkeeping + snapshot);

  // Single precision halves the populations; no snapshots, no snapshot scratch.
  const auto single = cases::load_case(cylinder_file, "standard",
                                       {"numerics.precision=single", "outputs.snapshots.times=[]"});
  EXPECT_DOUBLE_EQ(derive_units(single).memory_bytes, populations / 2 + force + bookkeeping);

  // 3D: Q = 19 and three force components.
  const auto sphere = cases::load_case(sphere_file, "standard", {"outputs.snapshots.times=[]"});
  const auto u3 = derive_units(sphere);
  const double nc3 = with_ghosts(u3.blocks[0]), nf3 = with_ghosts(u3.blocks[1]);
  EXPECT_DOUBLE_EQ(u3.memory_bytes, (nc3 + nf3) * 19 * 4 + nf3 * (3 * 8 + 8));
}

TEST(sim_units, CasesThatDoNotFitInMemoryAreRefusedNamingTheValueTheMachineAndTheFix) {
  const auto spec = cases::load_case(cylinder_file, "standard");
  const auto u = derive_units(spec);
  EXPECT_NO_THROW(check_memory(spec, u, 1024 * gib));
  EXPECT_NO_THROW(check_memory(spec, u, 0));  // unknown machine: nothing to compare with
  try {
    check_memory(spec, u, 0.5 * gib);
    ADD_FAILURE() << "a case of " << u.memory_bytes << " bytes fits in 0.5 GiB";
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.json_path(), "/numerics/grid/fine_spacing");
    for (const std::string w :
         {"cylinder_re100.json", "0.02", "GiB of memory", "memory of this machine: 0.5 GiB",
          "coarser resolution", "smaller domain", "\"single\""})
      EXPECT_NE(what.find(w), std::string::npos) << "no \"" << w << "\" in: " << what;
  }
  // The margin: 10 % of the machine, at least 512 MiB.
  EXPECT_DOUBLE_EQ(usable_memory_bytes(100 * gib), 90 * gib);
  EXPECT_DOUBLE_EQ(usable_memory_bytes(2 * gib), 1.5 * gib);
  // Just above and just below the usable memory.
  const double machine = (u.memory_bytes + memory_margin_bytes) * 1.001;
  EXPECT_NO_THROW(check_memory(spec, u, machine));
  EXPECT_THROW(check_memory(spec, u, u.memory_bytes * 1.05), core::InputError);
}

TEST(sim_units, ThisMachineHasMemory) { EXPECT_GT(machine_memory_bytes(), 64.0 * 1024 * 1024); }

TEST(sim_units, RunsLongerThanAnyStepCounterAreRefused) {
  // 1e300 L/U is a valid number of the format, but not a number of steps (the cast to an integer
  // would be undefined behaviour).
  const auto spec = cases::load_case(cylinder_file, "standard", {"numerics.end_time=1e300"});
  expect_refused(spec, "/numerics/end_time", "at most 1e+11 coarse time steps");
}

// Found by tests/fuzz/fuzz_case.cpp: Re = 1e-320 is a valid positive number, but 1/Re overflows
// to infinity and the relaxation time with it; a run shorter than one step has no steps.
TEST(sim_units, ReynoldsNumbersWhoseViscosityOverflowsAndRunsShorterThanAStepAreRefused) {
  const auto tiny_re = cases::load_case(cylinder_file, "standard", {"physics.reynolds=1e-320"});
  expect_refused(tiny_re, "/physics/reynolds", "a finite tau > 0.5");
  const auto short_run =
      cases::load_case(cylinder_file, "standard",
                       {"numerics.end_time=1e-300", "outputs.snapshots.times=[]", "outputs.average_from=0"});
  expect_refused(short_run, "/numerics/end_time", "at least one coarse time step");
}

// The summary's window statistics need three series rows after average_from; a shorter window
// used to fail at the end of the run (exit 4, after all the work). It is refused up front.
TEST(sim_units, AveragingWindowsWithFewerThanThreeSeriesRowsAreRefused) {
  const std::vector<std::string> short_window{"numerics.end_time=0.1", "outputs.snapshots.times=[0]",
                                              "outputs.average_from=0.05"};  // rows every 0.05 L/U
  expect_refused(cases::load_case(sphere_file, "standard", short_window), "/outputs/average_from", "this one holds 2");
  const auto ok = cases::load_case(sphere_file, "standard",
                                   {"numerics.end_time=0.2", "outputs.snapshots.times=[0]", "outputs.average_from=0.1"});
  const auto units = derive_units(ok);
  EXPECT_EQ(series_rows_in_window(ok, units), 3);  // t = 0.1, 0.15, 0.2 (to within a step)
  // The whole run: every row (end_time / interval of them) is in a window from 0.
  const auto whole = cases::load_case(sphere_file, "standard", {"outputs.average_from=0"});
  const auto whole_units = derive_units(whole);
  EXPECT_NEAR(series_rows_in_window(whole, whole_units), whole.numerics.end_time / whole.outputs.series.interval, 1.0);
}

// Every input in tests/fuzz/regressions/ (the format of tests/fuzz/fuzz_case.cpp) was once
// accepted or crashed; each must now be refused with an InputError by load or derive_units.
TEST(sim_units, FuzzRegressionsAreInputErrors) {
  int replayed = 0;
  for (const auto& entry : fs::directory_iterator(source_dir / "tests/fuzz/regressions")) {
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const fuzz::FuzzInput input = fuzz::split_fuzz_input(bytes);
    SCOPED_TRACE(entry.path().filename().string());
    EXPECT_THROW(
        {
          const auto spec = input.overrides.empty()
                                ? cases::load_case_text(input.text, "fuzz.json")
                                : cases::load_case(source_dir / fuzz::base_case_files()[input.base],
                                                   "standard", input.overrides);
          derive_units(spec);
        },
        core::InputError);
    ++replayed;
  }
  EXPECT_GE(replayed, 2);
}

// The stiffness factor of a law against NH of the same E is the ratio of its stiffest
// small-strain mode, measured here by finite differences of the laws' own energies
// (membrane/fem_membrane.hpp): the isotropic stretch (area modulus) and the pure shear.
TEST(sim_units, MembraneStiffnessFactorIsTheLawsStiffestModeAgainstNeoHookean) {
  auto energy = [](const membrane::MembraneLaw& law, double l1, double l2) {
    const double I1 = l1 * l1 + l2 * l2 - 2.0, I2 = l1 * l1 * l2 * l2 - 1.0;
    return std::visit([&](const auto& w) { return w.energy(I1, I2); }, law);
  };
  auto second_derivative = [&](const membrane::MembraneLaw& law, auto stretch) {
    const double h = 1e-4;
    auto W = [&](double e) {
      const auto [l1, l2] = stretch(e);
      return energy(law, l1, l2);
    };
    return (W(h) - 2.0 * W(0.0) + W(-h)) / (h * h);
  };
  auto isotropic = [](double e) { return std::pair{1.0 + e, 1.0 + e}; };
  auto shear = [](double e) { return std::pair{1.0 + e, 1.0 / (1.0 + e)}; };
  const double E = 1.0;
  const membrane::MembraneLaw nh = membrane::NeoHookean{E};
  for (double C : {0.1, 1.0, 23.0, 100.0, 400.0}) {
    SCOPED_TRACE(C);
    const membrane::MembraneLaw sk = membrane::Skalak{E, C};
    const double area = second_derivative(sk, isotropic) / second_derivative(nh, isotropic);
    const double shearing = second_derivative(sk, shear) / second_derivative(nh, shear);
    cases::MembraneSpec spec;
    spec.law = cases::MembraneSpec::Law::skalak;
    spec.area_dilation = C;
    EXPECT_NEAR(membrane_stiffness_factor(spec), std::max(area, shearing), 1e-5 * std::max(area, shearing));
  }
  for (auto law : {cases::MembraneSpec::Law::neo_hookean, cases::MembraneSpec::Law::zero_thickness,
                   cases::MembraneSpec::Law::hooke}) {
    cases::MembraneSpec spec;
    spec.law = law;
    EXPECT_EQ(membrane_stiffness_factor(spec), 1.0);
  }
  const membrane::MembraneLaw zt = membrane::ZeroThickness{E};
  EXPECT_NEAR(second_derivative(zt, isotropic), second_derivative(nh, isotropic), 1e-6);
  EXPECT_NEAR(second_derivative(zt, shear), second_derivative(nh, shear), 1e-6);
}

// No catalogue case, at any of its levels, runs a membrane above the explicit-coupling limit
// make stress measured (a case that would blow up within its first hundreds of steps: the
// chapter 6 biconcave cells did, at quick, before the Skalak factor entered the rule). The 3D
// cases are written by generators that keep E_lu at or below E_MAX = 0.5 with their own copy of
// the stiffness factor (scripts/capsule3d_catalogue.py): checking that bound here with the C++
// factor catches the two drifting apart.
TEST(sim_units, NoCatalogueMembraneIsAboveTheExplicitCouplingLimit) {
  int membranes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(source_dir / "catalogue")) {
    if (entry.path().extension() != ".json" || entry.path().filename() == "schema.json") continue;
    for (const auto& level : cases::fidelity_levels(entry.path())) {
      const auto spec = cases::load_case(entry.path(), level);
      const auto units = derive_units(spec);
      for (const auto& b : spec.physics.bodies) {
        if (!b.membrane) continue;
        ++membranes;
        const double E_lu = membrane_lattice_modulus(units, b);
        EXPECT_LE(E_lu, membrane_stiffness_limit(spec.physics.dimension))
            << entry.path() << " at " << level << ", body " << b.name;
        if (spec.physics.dimension == 3) {
          EXPECT_LE(E_lu, 0.5 * (1 + 1e-3)) << entry.path() << " at " << level << " (generators' E_MAX)";
        }
      }
    }
  }
  EXPECT_GT(membranes, 300);
}

// The advice for a block whose tau is close to 1/2 names what to change for the case's operator:
// TRT for BGK; for TRT a magic parameter down to (tau - 1/2)/2 (tau- = 1), and never a larger one
// than the case already has.
TEST(TauNearHalfCause, NamesTheChangeForTheOperator) {
  using Op = cases::CollisionSpec::Operator;
  const double tau = 0.51875;  // the cylinder at Re 200, quick, coarse block
  const std::string bgk = tau_near_half_cause({Op::bgk, 0.25, {}}, tau);
  EXPECT_NE(bgk.find("use the TRT operator"), std::string::npos) << bgk;

  const std::string trt = tau_near_half_cause({Op::trt, 1.0 / 12, {}}, tau);
  EXPECT_NE(trt.find("tau- = 1/2 + magic / (tau - 1/2) = 4.94"), std::string::npos) << trt;
  EXPECT_NE(trt.find("down to (tau - 1/2)/2 = 0.00938, which gives tau- = 1"), std::string::npos) << trt;

  const std::string small = tau_near_half_cause({Op::trt, 0.005, {}}, tau);
  EXPECT_EQ(small.find("a smaller numerics.collision.magic"), std::string::npos) << small;
  EXPECT_NE(small.find("already relax fast here (magic 0.005, tau- = 0.767)"), std::string::npos) << small;

  for (const auto& s : {bgk, trt, small}) {
    EXPECT_EQ(s.rfind("tau = 0.5188 on this block is close to 1/2", 0), 0u) << s;
    EXPECT_NE(s.find("a finer grid or a higher numerics.lattice_velocity"), std::string::npos) << s;
  }
}

}  // namespace
}  // namespace caplab::sim
