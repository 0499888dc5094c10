// The live-parameter table. Defaults come from published measurements of the prostate; each entry's
// comment says where, and the edge-spring conversion rule lives in springs.cpp.
#include "rtcore/tissue/tissue_parameters.h"

#include <cmath>
#include <string>

#include "rtcore/base/checked_number.h"

namespace resecto {
namespace {

// Stiffness: Krouskop et al., "Elastic moduli of breast and prostate tissues under compression",
// Ultrasonic Imaging 20:260-274 (1998): benign prostatic hyperplasia 36-41 kPa, normal gland 55-69 kPa,
// cancer 96-241 kPa. The range covers soft oedematous tissue to a hard carcinoma.
// Viscosity: a 1 ms relaxation time at the default modulus (eta = E * tau) damps the mesh's fastest
// modes without visibly slowing the gland's slow ones (Zhang et al., Ultrasound Med Biol 34 (2008):
// prostate viscosity of the order of 1-10 Pa*s at low frequency; the default is above that so that
// the coarse mesh's own ringing is damped).
// Density: soft tissue, 1.05 g/cm^3 (the anatomy's ProstateShape::tissue_density_kg_m3).
// Anchor: the endopelvic fascia and puboprostatic ligaments let the gland shift a few millimetres under
// the sheath: 1 kPa per mm of displacement over the ~60 cm^2 capsule is ~6 N per mm for the whole gland.
// Penalty: per contact point; 0.2 N/mm keeps the loop's penetration a tenth of a millimetre at the
// ~1 N forces of a 5 mm indentation.
constexpr TissueParameterSpec kSpecs[] = {
    {TissueParameter::kStiffness, "stiffness", "kPa", 40.0, 1.0, 500.0, 1e3,
     "Young's modulus of the gland, turned into edge spring stiffness (BPH: 36-41 kPa)"},
    {TissueParameter::kSpringDamping, "spring_damping", "Pa*s", 40.0, 0.0, 5000.0, 1.0,
     "viscosity of the tissue, turned into edge dampers like the stiffness"},
    {TissueParameter::kViscousDamping, "viscous_damping", "1/s", 20.0, 0.0, 2000.0, 1.0,
     "global damping: force -rate * mass * velocity on every node"},
    {TissueParameter::kDensity, "density", "g/cm^3", 1.05, 0.5, 2.0, 1e3,
     "tissue density, lumped onto the nodes from the tetrahedra's volumes"},
    {TissueParameter::kAnchorStiffness, "anchor_stiffness", "kPa/mm", 1.0, 0.01, 100.0, 1e6,
     "support of the capsule's outer surface by the pelvis, per unit area and displacement"},
    {TissueParameter::kPenaltyStiffness, "penalty_stiffness", "N/mm", 0.2, 0.01, 10.0, 1e3,
     "contact stiffness per penetrating point (tissue node in the tool, tool vertex in the tissue)"},
    {TissueParameter::kPenaltyDamping, "penalty_damping", "N*s/m", 0.05, 0.0, 10.0, 1.0,
     "contact damping per penetrating point, on the approach speed along the contact normal"},
    {TissueParameter::kCuttingRadius, "cutting_radius", "mm", 1.0, 0.2, 3.0, 1e-3,
     "reach of the loop wire when the cutting pedal is pressed (used by resection)"},
};
static_assert(std::size(kSpecs) == kTissueParameterCount);

}  // namespace

std::span<const TissueParameterSpec> tissue_parameter_specs() { return kSpecs; }

const TissueParameterSpec& tissue_parameter_spec(TissueParameter id) { return kSpecs[static_cast<std::size_t>(id)]; }

std::optional<TissueParameter> find_tissue_parameter(std::string_view key) {
  for (const TissueParameterSpec& spec : kSpecs) {
    if (spec.key == key) return spec.id;
  }
  return std::nullopt;
}

TissueParameters::TissueParameters() {
  for (const TissueParameterSpec& spec : kSpecs) values[static_cast<std::size_t>(spec.id)] = spec.default_value;
}

double TissueParameters::si(TissueParameter id) const { return get(id) * tissue_parameter_spec(id).si_per_unit; }

Status TissueParameters::set(TissueParameter id, double value) {
  const TissueParameterSpec& spec = tissue_parameter_spec(id);
  if (!std::isfinite(value) || value < spec.min_value || value > spec.max_value) {
    // Exact values: "%g" printed 3.0000000000000004 as 3, so "3 is out of range [0.2, 3]".
    return Error{"parameter " + std::string(spec.key) + " = " + exact_number(value) + " is out of range [" +
                 exact_number(spec.min_value) + ", " + exact_number(spec.max_value) + "] " + std::string(spec.unit)};
  }
  values[static_cast<std::size_t>(id)] = value;
  return Ok{};
}

Status TissueParameters::set_from_assignment(std::string_view assignment) {
  const std::size_t equals = assignment.find('=');
  if (equals == std::string_view::npos) {
    return Error{"--set " + std::string(assignment) + ": expected KEY=VALUE"};
  }
  const std::string_view key = assignment.substr(0, equals);
  const std::string_view text = assignment.substr(equals + 1);
  const std::optional<TissueParameter> id = find_tissue_parameter(key);
  if (!id) return Error{"--set " + std::string(assignment) + ": unknown parameter '" + std::string(key) + "' (see resecto params)"};
  // parse_finite, as every other number on the command line is read: from_chars alone refused "+40".
  const std::optional<double> value = parse_finite(text);
  if (!value) return Error{"--set " + std::string(assignment) + ": '" + std::string(text) + "' is " + not_finite_kind(text)};
  if (Status status = set(*id, *value); !status) return Error{"--set " + std::string(assignment) + ": " + status.error()};
  return Ok{};
}

}  // namespace resecto
