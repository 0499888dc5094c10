// Re-scoring a recording: open it, refuse what cannot be scored faithfully (naming why), re-simulate
// it through the core with the ScoreTracker observing every collision step, verify every recorded
// state hash on the way.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "rtcore/base/result.h"
#include "rtcore/metrics/score.h"

namespace resecto {

/// A recording's score and where it came from.
struct RecordingScore {
  std::string file;
  std::string procedure;       ///< as the recording's header names it
  std::uint64_t ticks = 0;
  std::uint64_t verified_hashes = 0;
  /// The gland's surface triangles (the model's resolution: scores of different ones differ).
  std::uint32_t surface_triangles = 0;
  /// The signal that ended the run before its procedure did ("SIGINT"), or empty when it ran to its end.
  std::string interrupted;
  /// Why a damaged or interrupted file was scored anyway, or empty.
  std::string note;
  ProcedureScore score;
};

/// Called now and then with the ticks done and to do.
using ScoreProgress = std::function<void(std::uint64_t done, std::uint64_t total)>;

/// An error (naming the file and the reason) for an unreadable, damaged, cut or unfaithful recording.
Result<RecordingScore> score_recording(const std::filesystem::path& path, const ScoreProgress& progress = {});

/// The metrics as JSON: numbers in their units, the lobe order by name, the unavailable ones null
/// with "available": false beside them.
nlohmann::ordered_json score_metrics_json(const ScoreMetrics& m);

/// The cohort CSV: one header line, one row per recording (same columns as score_metrics_json, the
/// lobe order as names joined by '>').
std::string score_csv_header();
std::string score_csv_row(const RecordingScore& s);

}  // namespace resecto
