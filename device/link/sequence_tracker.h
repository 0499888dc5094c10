// SequenceTracker: classifies each valid report by its sequence number — next in order, after a gap
// (lost reports), a duplicate, or a late arrival (out of order, filling a gap counted as lost) — over
// a sliding window of the most recent sequence numbers. Fixed size, no allocation.
#pragma once

#include <array>
#include <cstdint>

namespace resecto {

/// The verdict on one sequence number.
enum class SequenceVerdict : std::uint8_t {
  kFirst,       ///< first report since reset: nothing to compare with
  kNext,        ///< newer than every report so far (possibly after a gap)
  kDuplicate,   ///< already seen
  kLate,        ///< older than the newest, not seen before: arrived out of order
  kStale,       ///< older than the window can tell
  kRestart,     ///< far behind the newest: the board restarted its count
};

/// Tracks 32-bit wrapping sequence numbers as 64-bit ones.
class SequenceTracker {
 public:
  static constexpr std::uint64_t kWindow = 1024;  ///< how far back duplicates and late reports are told apart

  /// Forget everything (after a reconnection).
  void reset();
  /// Classifies `sequence32`; for kNext, `gap` receives how many numbers were skipped.
  SequenceVerdict observe(std::uint32_t sequence32, std::uint64_t& unwrapped, std::uint64_t& gap);
  bool has_newest() const { return started_; }
  std::uint64_t newest() const { return newest_; }

 private:
  bool seen(std::uint64_t sequence) const;
  void mark(std::uint64_t sequence);
  void clear_range(std::uint64_t first, std::uint64_t last_inclusive);

  std::array<std::uint64_t, kWindow / 64> bits_{};  ///< bit (s % kWindow) set when s was seen
  std::uint64_t newest_ = 0;  ///< largest unwrapped sequence accepted (offset by 2^32 to stay positive)
  bool started_ = false;
};

}  // namespace resecto
