// The spelling in case files of every enumeration of CaseSpec, written once.
//
// Each table maps the JSON string to the C++ enumerator. The case schema takes its allowed
// values from these tables and the loader converts with them, so a new enumerator is added
// here and nowhere else (catalogue/schema.json lists the same strings; a unit test checks).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "case/case_spec.hpp"
#include "core/error.hpp"

namespace caplab::cases {

/// One entry of an enumeration table: the case-file spelling and the enumerator.
template <class E>
struct EnumName {
  std::string_view name;
  E value;
};

inline constexpr std::array flow_type_names{
    EnumName<FlowSpec::Type>{"rest", FlowSpec::Type::rest},
    EnumName<FlowSpec::Type>{"uniform", FlowSpec::Type::uniform},
    EnumName<FlowSpec::Type>{"shear", FlowSpec::Type::shear},
    EnumName<FlowSpec::Type>{"body_force", FlowSpec::Type::body_force},
    EnumName<FlowSpec::Type>{"taylor_green", FlowSpec::Type::taylor_green}};

inline constexpr std::array boundary_names{EnumName<BoundaryType>{"periodic", BoundaryType::periodic},
                                           EnumName<BoundaryType>{"far_field", BoundaryType::far_field},
                                           EnumName<BoundaryType>{"wall", BoundaryType::wall}};

inline constexpr std::array shape_type_names{EnumName<ShapeSpec::Type>{"circle", ShapeSpec::Type::circle},
                                             EnumName<ShapeSpec::Type>{"ellipse", ShapeSpec::Type::ellipse},
                                             EnumName<ShapeSpec::Type>{"biconcave", ShapeSpec::Type::biconcave},
                                             EnumName<ShapeSpec::Type>{"sphere", ShapeSpec::Type::sphere},
                                             EnumName<ShapeSpec::Type>{"oblate_spheroid", ShapeSpec::Type::oblate_spheroid},
                                             EnumName<ShapeSpec::Type>{"biconcave_discoid", ShapeSpec::Type::biconcave_discoid}};

inline constexpr std::array membrane_law_names{
    EnumName<MembraneSpec::Law>{"hooke", MembraneSpec::Law::hooke},
    EnumName<MembraneSpec::Law>{"neo_hookean", MembraneSpec::Law::neo_hookean},
    EnumName<MembraneSpec::Law>{"zero_thickness", MembraneSpec::Law::zero_thickness},
    EnumName<MembraneSpec::Law>{"skalak", MembraneSpec::Law::skalak}};

inline constexpr std::array reference_curvature_names{
    EnumName<MembraneSpec::ReferenceCurvature>{"initial", MembraneSpec::ReferenceCurvature::initial},
    EnumName<MembraneSpec::ReferenceCurvature>{"circle", MembraneSpec::ReferenceCurvature::circle},
    EnumName<MembraneSpec::ReferenceCurvature>{"flat", MembraneSpec::ReferenceCurvature::flat}};

inline constexpr std::array motion_type_names{
    EnumName<RigidMotionSpec::Type>{"fixed", RigidMotionSpec::Type::fixed},
    EnumName<RigidMotionSpec::Type>{"prescribed", RigidMotionSpec::Type::prescribed}};

inline constexpr std::array refinement_names{
    EnumName<GridSpec::Refinement>{"uniform", GridSpec::Refinement::uniform},
    EnumName<GridSpec::Refinement>{"two_level", GridSpec::Refinement::two_level}};

inline constexpr std::array collision_names{
    EnumName<CollisionSpec::Operator>{"bgk", CollisionSpec::Operator::bgk},
    EnumName<CollisionSpec::Operator>{"trt", CollisionSpec::Operator::trt}};

inline constexpr std::array precision_names{EnumName<Precision>{"double", Precision::double_},
                                            EnumName<Precision>{"single", Precision::single}};

inline constexpr std::array far_field_names{
    EnumName<FarFieldScheme>{"extrapolation", FarFieldScheme::extrapolation},
    EnumName<FarFieldScheme>{"equilibrium", FarFieldScheme::equilibrium}};

inline constexpr std::array kernel_names{EnumName<IbSpec::Kernel>{"cosine4", IbSpec::Kernel::cosine4},
                                         EnumName<IbSpec::Kernel>{"roma3", IbSpec::Kernel::roma3},
                                         EnumName<IbSpec::Kernel>{"linear2", IbSpec::Kernel::linear2}};

/// Allowed values of `acceptance[].comparison` (kept as a string in AcceptanceSpec).
inline constexpr std::array<std::string_view, 2> comparison_names{"relative", "absolute"};

/// The case-file spellings of a table, in table order.
template <class Table>
std::vector<std::string> enum_names(const Table& table) {
  std::vector<std::string> names;
  for (const auto& entry : table) names.emplace_back(entry.name);
  return names;
}

/// The enumerator spelled `name`; throws core::Error if there is none (the schema check
/// runs first, so this is an internal error, not an input error).
template <class Table>
auto enum_value(const Table& table, std::string_view name) {
  for (const auto& entry : table)
    if (entry.name == name) return entry.value;
  throw core::Error("internal: no enumerator named '" + std::string(name) + "'");
}

/// The case-file spelling of `value`.
template <class Table, class E>
std::string enum_name(const Table& table, E value) {
  for (const auto& entry : table)
    if (entry.value == value) return std::string(entry.name);
  throw core::Error("internal: enumerator without a name");
}

}  // namespace caplab::cases
