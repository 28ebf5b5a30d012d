// Fluid throughput: million lattice-node updates per second (MLUPS) of sim::Fluid::step().
//
// The box is periodic on every axis, so one step is the fused collide-and-push kernel, the
// periodic boundary stage and the buffer swap. The flow is a uniform velocity with a small
// Taylor–Green perturbation: it neither decays to rest (no subnormal numbers) nor diverges.
// Two-level: the coarse box with a centred fine block (m = 2) covering about 1/8 of its
// volume; one step is one coarse step, two fine substeps and the coupling, and counts
// coarse + 2 × fine interior nodes, less the covered coarse nodes (Fluid::updates_per_step).
// Timing: one warm-up step, then batches of steps (each about 1/5 of the minimum time) until
// the minimum time has passed and at least three batches ran; a two-level case alternates its
// batches with those of its uniform twin (same coarse box), and its overhead is the median of
// the per-pair speed ratios. The process CPU time over the window tells whether the threads
// had the cores to themselves (cpu_share).
#pragma once

#include <array>
#include <string>
#include <vector>

namespace caplab::bench {

/// One configuration to measure.
struct FluidCase {
  std::string lattice;    // "D2Q9" | "D3Q19"
  std::string collision;  // "bgk" | "trt"
  std::string precision;  // "double" | "float"
  int threads = 1;
  int n = 0;  // interior nodes per axis of the (coarse) box
  bool two_level = false;
};

struct FluidMeasurement {
  std::vector<int> size;       // interior nodes per axis of the (coarse) box
  std::vector<int> fine_size;  // two-level only
  double fine_fraction = 0;    // covered share of the coarse volume (two-level)
  double updates_per_step = 0;
  long steps = 0;
  double seconds = 0;           // measured window (warm-up excluded)
  double mlups = 0;             // steps × updates / seconds over the window
  double mlups_best = 0;        // best batch
  double coupling_seconds = 0;  // two-level coupling time inside the window
  /// Two-level: MLUPS of the uniform box of the same coarse size, timed in batches alternating
  /// with the two-level ones (a same-moment reference for the overhead).
  double uniform_twin_mlups = 0;
  /// Two-level: median over the batch pairs of uniform-twin MLUPS / two-level MLUPS, minus 1.
  double overhead = 0;
  /// Process CPU time / (threads × wall time) over the window: well below 1 means the threads
  /// were descheduled (other work on the machine) and the timing is contended.
  double cpu_share = 0;
  std::size_t bytes_per_update = 0;                 // Populations::bytes_per_update()
};

/// Supported names, for validation and messages.
const std::vector<std::string>& supported_lattices();
const std::vector<std::string>& supported_collisions();
const std::vector<std::string>& supported_precisions();

/// Measures one configuration for at least `min_seconds`. Throws core::InputError for an
/// unsupported combination and core::Error if the flow is not finite afterwards.
FluidMeasurement measure_fluid(const FluidCase& c, double min_seconds);

}  // namespace caplab::bench
