// Snapshots of a run (snapshots.h5 + snapshots.xdmf, DESIGN.md section 6), readable in
// ParaView (XDMF 3 reader) and by any HDF5 tool.
//
// HDF5 layout, one group per output step (the step index counts outputs, not solver steps):
//   /step_000012                      attribute "time"
//   /step_000012/fine/<scalar>        float64 [nz][ny][nx] (3D) or [ny][nx] (2D), x fastest
//   /step_000012/fine/<vector>        float64 [nz][ny][nx][3] or [ny][nx][3] (2D padded with 0)
//                                     block attributes "n" (x, y[, z]), "origin", "dx"
//   /step_000012/capsule/points       float64 [N][3] (2D: z = 0)
//   /step_000012/capsule/connectivity int32 [M][D] (2D: segments of a polyline; 3D: triangles)
//   /step_000012/capsule/<field>      float64 [N] or [N][3]
//
// XDMF: a temporal collection of steps, each a spatial collection of the blocks and meshes
// written with the same time. XDMF lists structured dimensions, origin and spacing slowest
// axis first (z, y, x). A 2D block is written as a 3DCoRectMesh with one layer in z
// (Dimensions "1 ny nx"): ParaView maps a 2DCoRectMesh onto its y-z plane, which would put the
// fields at right angles to the 2D membrane meshes (in the x-y plane) and their vectors.
// The .xdmf is rewritten atomically after every addition, once the HDF5 file is flushed, so
// it is always valid and refers only to data on disk.
//
// Not thread-safe (serial HDF5): one writer is driven from one thread.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/vec.hpp"
#include "field/grid.hpp"

namespace caplab::io {

/// Writer of snapshots.h5 and its XDMF index (see the file header for the layout).
/// D = 2 or 3.
template <int D>
class SnapshotWriter {
 public:
  /// Scalar fields by name, viewing the caller's storage (no copy).
  using ScalarFields = std::map<std::string, std::span<const double>>;
  /// Vector fields on a grid by name: D components, each viewing the caller's storage (SoA,
  /// as field::VectorField::comp).
  using GridVectorFields = std::map<std::string, std::array<std::span<const double>, D>>;
  /// Vector fields on mesh points by name, one Vec<D> per point.
  using PointVectorFields = std::map<std::string, std::span<const Vec<D>>>;

  /// Creates (truncates) `h5_file`; `xdmf_file` is written at the first step. The XDMF refers
  /// to the data as `h5_href` (default: the file name of `h5_file`), relative to the .xdmf:
  /// with a RunDirectory, write to run.partial_path("snapshots.h5") with href "snapshots.h5"
  /// and commit_file("snapshots.h5") after close(). `attributes` (a JSON object) become string
  /// attributes of the root group.
  SnapshotWriter(std::filesystem::path h5_file, std::filesystem::path xdmf_file, std::string h5_href = {},
                 const nlohmann::json& attributes = nlohmann::json::object());
  /// Reopens `h5_file`, written by a writer whose index() was `index`, to continue it (a
  /// resumed run): steps written after that index are removed and the XDMF rewritten. Throws
  /// core::Error when the file cannot be opened or lacks a step of the index.
  static SnapshotWriter reopen(std::filesystem::path h5_file, std::filesystem::path xdmf_file, std::string h5_href,
                               const nlohmann::json& index);
  /// The steps written so far (their times, groups and XDMF grids), for a checkpoint.
  nlohmann::json index() const;
  /// Closes the file if close() was not called; errors are swallowed here, so call close().
  ~SnapshotWriter();
  SnapshotWriter(SnapshotWriter&&) noexcept;
  SnapshotWriter& operator=(SnapshotWriter&&) noexcept;
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;

  /// Adds the node fields of block `block_name` (e.g. "coarse", "fine") at `time`. Each array
  /// holds either the interior nodes only (grid.interior_size() values, x fastest) or the
  /// whole field with its ghost layer (grid.size() values, the layout of field::Grid); ghost
  /// values are not written. Calls with the same `time` as the last step add to that step;
  /// a new step needs a later time. Example:
  ///   writer.add_grid_field_step(t, grid, "fine", {{"rho", rho}}, {{"u", {ux, uy}}});
  void add_grid_field_step(double time, const field::Grid<D>& grid, const std::string& block_name,
                           const ScalarFields& scalar_fields, const GridVectorFields& vector_fields = {});

  /// Adds the Lagrangian mesh `name` at `time` (same step rule as above): `points` (N nodes),
  /// `cells` (2D: segments {a, b}, a closed ring of N nodes being {i, (i+1) % N}; 3D:
  /// triangles {a, b, c}), point fields with N values each.
  void add_mesh_step(double time, const std::string& name, std::span<const Vec<D>> points,
                     std::span<const std::array<int, D>> cells, const ScalarFields& point_scalars = {},
                     const PointVectorFields& point_vectors = {});

  /// Closes the HDF5 file; further additions throw. Idempotent.
  void close();

  /// Number of output steps written so far.
  std::size_t steps() const;
  const std::filesystem::path& h5_file() const;
  const std::filesystem::path& xdmf_file() const;

 private:
  SnapshotWriter();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Segments {i, (i+1) % n} of a closed ring of n nodes, for add_mesh_step in 2D.
std::vector<std::array<int, 2>> closed_ring_segments(int n);

extern template class SnapshotWriter<2>;
extern template class SnapshotWriter<3>;

}  // namespace caplab::io
