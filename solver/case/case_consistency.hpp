// Checks of a case that involve more than one value: lengths per dimension, grid spacing
// against domain and fine block, block and body placement, output times against the end time,
// tolerances against fidelity levels. They run on the typed CaseSpec after the schema pass
// (case_schema.hpp), so types and single-value ranges are already known to be right.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "case/case_diagnostics.hpp"
#include "case/case_spec.hpp"
#include "geometry/closed_curve.hpp"
#include "geometry/triangle_mesh.hpp"

namespace caplab::cases {

/// Most lattice nodes a case may ask for (all blocks together); more is surely a typo.
inline constexpr double max_lattice_nodes = 2e9;
/// Relative tolerance for "is a whole multiple of the spacing".
inline constexpr double spacing_tolerance = 1e-9;
/// Fine block faces keep this many coarse spacings from the domain faces.
inline constexpr int fine_region_margin_coarse = 4;
/// Bodies keep this many fine spacings from the fine block faces (IB kernel support).
inline constexpr int body_margin_fine = 3;
/// Capsule membrane nodes at most this many fine spacings apart (beyond it the fluid leaks).
inline constexpr double max_membrane_spacing_fine = 2.0;

/// The rest shape of a 2D capsule as the geometry module describes it.
geometry::RingShape ring_shape(const ShapeSpec& shape);

/// The rest mesh of a 3D capsule, centred at the origin, in L (thesis section 5.1.2).
geometry::TriangleMesh capsule_mesh(const ShapeSpec& shape, int subdivisions);

/// Checks that a membrane object (at JSON pointer `at`, of body `body`) has the keys of its
/// dimension and law and no others: 2D "nodes" (and the bending keys), 3D "subdivisions",
/// "skalak" "area_dilation"; the law itself matches the dimension.
void check_membrane_keys(const nlohmann::json& membrane, const std::string& at, const std::string& body,
                         int dimension, const CaseDiagnostics& diag);

/// Checks that every array listed in `per_axis_pointers` has `dimension` entries.
void check_axis_lengths(const nlohmann::json& doc, int dimension,
                        const std::vector<std::string>& per_axis_pointers, const CaseDiagnostics& diag);

/// Checks the cross-value rules listed above; throws core::InputError at the first violation.
/// `levels` are the fidelity levels the case defines.
void check_consistency(const CaseSpec& spec, const std::vector<std::string>& levels,
                       const CaseDiagnostics& diag);

}  // namespace caplab::cases
