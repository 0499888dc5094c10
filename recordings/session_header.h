// The recording's header chunk: who wrote it (format version, build), and everything a replay needs
// to rebuild the same core: the SimulationConfig field by field (model, rates, parameters, gimbal
// registration, filter, tissue choices), plus the run's description (procedure, mode, seed, the
// device calibration) and the keyframes' fixed quantisation grid. Stored as JSON: doubles are
// written with 17 significant digits, so they read back bit-exactly.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtcore/base/result.h"
#include "rtcore/core/simulation.h"
#include "recordings/keyframe_codec.h"

namespace resecto::rec {

/// What the recording says about the run it came from.
struct SessionHeader {
  std::uint32_t format_version = 0;
  std::string build;                ///< "resecto 0.1.0 (GCC 12.2.0, RelWithDebInfo)"
  SimulationConfig simulation;      ///< replay builds its Simulation from exactly this
  std::string procedure;            ///< name of the scripted procedure ("demo"), or empty
  std::string mode;                 ///< "batch", "realtime" or "console"
  std::uint64_t seed = 0;           ///< the emulated sensors' noise seed
  nlohmann::ordered_json calibration;  ///< the device calibration file's content (null if none)
  std::int64_t start_tick = 0;      ///< the first tick recorded
  int keyframe_every_steps = 6;     ///< a keyframe every this many collision steps
  QuantisationGrid grid;            ///< every keyframe's position grid
  std::uint32_t surface_triangles = 0;  ///< at the start
  std::uint32_t nodes = 0;              ///< mesh nodes at the start
  std::uint32_t metric_words = 0;       ///< 8-byte fields of ProcedureMetrics recorded per step
};

/// The most mesh nodes and surface triangles any keyframe of a recording with these settings can hold:
/// well past what the core's reserved room for refinement allows. A reader sizes nothing by a count
/// the file claims beyond these (a header or keyframe claiming a billion nodes is refused, not
/// allocated).
std::size_t most_nodes(const SimulationConfig& config);
std::size_t most_surface_triangles(const SimulationConfig& config);
/// The fewest surface triangles the gland a header's settings build has at the start (before any cut).
std::size_t least_surface_triangles(const SimulationConfig& config);

/// This build's identity string.
std::string build_identity();

/// The header as the JSON the header chunk stores.
nlohmann::ordered_json header_to_json(const SessionHeader& header);
/// Parses a header chunk's payload; the error names the field that is missing or malformed.
Result<SessionHeader> header_from_json(std::string_view text);

}  // namespace resecto::rec
