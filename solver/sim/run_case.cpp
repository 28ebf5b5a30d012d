#include "sim/run_case.hpp"

#include "core/threads.hpp"
#include "io/manifest.hpp"
#include "lattice/lattice.hpp"

namespace caplab::sim {

namespace {

template <class L, class T, class Op>
RunResult run_scene(const cases::CaseSpec& spec, const LatticeUnits& units, const Op& op, io::RunDirectory& dir,
                    const ProgressFn& progress) {
  Scene<L, T, Op> scene(spec, units, op);
  return scene.run(dir, progress);
}

template <class L, class T>
RunResult dispatch_operator(const cases::CaseSpec& spec, const LatticeUnits& units, io::RunDirectory& dir,
                            const ProgressFn& progress) {
  const double tau = units.blocks[0].tau;
  if (spec.numerics.collision.op == cases::CollisionSpec::Operator::trt)
    return run_scene<L, T>(spec, units, collision::Trt{tau, spec.numerics.collision.magic}, dir, progress);
  return run_scene<L, T>(spec, units, collision::Bgk{tau}, dir, progress);
}

template <class L>
RunResult dispatch_precision(const cases::CaseSpec& spec, const LatticeUnits& units, io::RunDirectory& dir,
                             const ProgressFn& progress) {
  if (spec.numerics.precision == cases::Precision::single) return dispatch_operator<L, float>(spec, units, dir, progress);
  return dispatch_operator<L, double>(spec, units, dir, progress);
}

}  // namespace

std::string supported_combinations() { return "dimension 2 (D2Q9) or 3 (D3Q19) × precision double|single × collision bgk|trt"; }

RunResult run_case(const cases::CaseSpec& spec, const std::filesystem::path& out, const ProgressFn& progress) {
  const LatticeUnits units = derive_units(spec);  // input errors surface before the directory exists
  const int threads = core::apply_thread_count(spec.numerics.threads);
  auto dir = io::RunDirectory::create(out, /*overwrite=*/true);
  nlohmann::json resolved = spec.resolved;
  resolved["fidelity_applied"] = spec.fidelity;
  dir.write_json("case.json", resolved);
  dir.update_manifest({{"case_id", spec.id},
                       {"fidelity", spec.fidelity},
                       {"case_file", spec.source_file},
                       {"threads", threads},
                       {"environment", io::environment_json(threads)},
                       {"lattice", units.to_json()}});
  try {
    RunResult r = spec.physics.dimension == 2 ? dispatch_precision<lattice::D2Q9>(spec, units, dir, progress)
                                              : dispatch_precision<lattice::D3Q19>(spec, units, dir, progress);
    dir.write_json("summary.json", r.summary);
    nlohmann::json share = nlohmann::json::object();
    for (const auto& [k, v] : r.stage_seconds.items()) share[k] = v.get<double>() / r.wall_seconds;
    dir.finish("ok", {{"wall_time_s", r.wall_seconds},
                      {"steps", r.steps},
                      {"mlups", r.mlups},
                      {"stage_seconds", r.stage_seconds},
                      {"stage_share", share}});
    return r;
  } catch (const core::NumericalError& e) {
    dir.finish("diverged", {{"error", e.what()}, {"step", e.step()}, {"where", e.where()}, {"cause", e.cause()}});
    throw;
  } catch (const core::InputError& e) {
    dir.finish("input_error", {{"error", e.what()}});
    throw;
  } catch (const std::exception& e) {
    dir.finish("failed", {{"error", e.what()}});
    throw;
  }
}

}  // namespace caplab::sim
