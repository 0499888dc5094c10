// The tissue's live parameters: one table of key, unit, default and range that the command line,
// the console and the core share, and the command that changes a value at a tick boundary.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "rtcore/base/result.h"

namespace resecto {

/// Every live tissue parameter, in table order.
enum class TissueParameter : std::uint8_t {
  kStiffness,         ///< Young's modulus behind the edge springs
  kSpringDamping,     ///< tissue viscosity behind the edge dampers
  kViscousDamping,    ///< mass-proportional (global) damping rate
  kDensity,
  kAnchorStiffness,   ///< capsule-to-pelvis support per unit capsule area
  kPenaltyStiffness,  ///< per contact point
  kPenaltyDamping,    ///< per contact point
  kCuttingRadius,     ///< the loop's reach when resecting (read by resection)
  kCount
};
inline constexpr std::size_t kTissueParameterCount = static_cast<std::size_t>(TissueParameter::kCount);

/// A parameter as users see it: edge units (kPa, mm, g/cm^3), with the factor to SI.
struct TissueParameterSpec {
  TissueParameter id;
  std::string_view key;
  std::string_view unit;
  double default_value;
  double min_value;
  double max_value;
  double si_per_unit;  ///< SI value = edge value * si_per_unit
  std::string_view description;
};

/// The table, in TissueParameter order.
std::span<const TissueParameterSpec> tissue_parameter_specs();
const TissueParameterSpec& tissue_parameter_spec(TissueParameter id);
/// The parameter named `key`, if there is one.
std::optional<TissueParameter> find_tissue_parameter(std::string_view key);

/// Current values in edge units, indexed by TissueParameter; starts at the defaults.
struct TissueParameters {
  std::array<double, kTissueParameterCount> values{};

  TissueParameters();
  double get(TissueParameter id) const { return values[static_cast<std::size_t>(id)]; }
  /// The value in SI units (Pa, Pa*s, 1/s, kg/m^3, N/m^3, N/m, N*s/m, m).
  double si(TissueParameter id) const;
  /// Sets a value after checking it lies in [min, max]; the error names the key, the value and the range.
  Status set(TissueParameter id, double value);
  /// Parses "KEY=VALUE" (edge units) and sets it; errors name the unknown key or the bad value.
  Status set_from_assignment(std::string_view assignment);
};

/// A parameter change the console queues for the core: applied before tick `apply_tick` runs.
struct ParameterCommand {
  std::int64_t apply_tick = 0;
  TissueParameter id = TissueParameter::kStiffness;
  double value = 0.0;  ///< edge units, already validated
};

}  // namespace resecto
